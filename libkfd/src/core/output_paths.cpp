#include "kfd/core/output_paths.h"

#include <random>
#include <system_error>

namespace kfd {
namespace fs = std::filesystem;

bool samePath(const fs::path& a, const fs::path& b) {
    if (a.empty() || b.empty()) return false;
    std::error_code ea, eb, ec;
    if (fs::exists(a, ea) && fs::exists(b, eb)) {
        const bool same = fs::equivalent(a, b, ec);
        if (!ec) return same;
    }
    const fs::path ca = fs::weakly_canonical(fs::absolute(a, ea), ea);
    const fs::path cb = fs::weakly_canonical(fs::absolute(b, eb), eb);
    if (ea || eb) return fs::absolute(a).lexically_normal() == fs::absolute(b).lexically_normal();
    return ca == cb;
}

void checkOutputPaths(const std::vector<NamedPath>& inputs, const std::vector<NamedPath>& outputs) {
    for (std::size_t i = 0; i < outputs.size(); ++i) {
        const NamedPath& o = outputs[i];
        if (o.path.empty()) continue;
        for (const NamedPath& in : inputs)
            if (samePath(o.path, in.path))
                throw PathError("the " + o.role + " " + o.path + " is the " + in.role + " " +
                                    in.path + ": refusing to overwrite an input",
                                o.path);
        for (std::size_t j = 0; j < i; ++j)
            if (samePath(o.path, outputs[j].path))
                throw PathError("the " + o.role + " " + o.path + " is also the " + outputs[j].role +
                                    " " + outputs[j].path,
                                o.path);
    }
}

fs::path temporaryPathFor(const fs::path& final_path) {
    static std::mt19937_64 rng{std::random_device{}()};
    const fs::path dir = final_path.parent_path();
    // The extension stays last: some writers choose the format by it (PNG).
    const std::string stem = final_path.stem().string(), ext = final_path.extension().string();
    for (int attempt = 0; attempt < 100; ++attempt) {
        const fs::path p = dir / ("." + stem + ".kfd-tmp-" + std::to_string(rng() % 1000000) + ext);
        std::error_code ec;
        if (!fs::exists(fs::symlink_status(p, ec))) return p;
    }
    throw PathError("cannot find a free temporary name beside " + final_path.string(),
                    final_path.string());
}

TempOutputFile::TempOutputFile(fs::path final_path)
    : final_(std::move(final_path)), temp_(temporaryPathFor(final_)) {}

TempOutputFile::~TempOutputFile() {
    if (committed_) return;
    std::error_code ec;
    fs::remove(temp_, ec);
}

void TempOutputFile::commit() {
    std::error_code ec;
    fs::rename(temp_, final_, ec);
    if (ec)
        throw PathError(
            "cannot move " + temp_.string() + " to " + final_.string() + ": " + ec.message(),
            final_.string());
    committed_ = true;
}

StagedOutputFolder::StagedOutputFolder(fs::path final_dir) : final_(std::move(final_dir)) {
    std::error_code ec;
    if (final_.filename().empty()) final_ = final_.parent_path();  // "out/" -> "out"
    const auto st = fs::status(final_, ec);
    if (fs::exists(st) && !fs::is_directory(st))
        throw PathError("the output folder " + final_.string() + " is not a folder",
                        final_.string());
    if (fs::is_directory(st)) {
        staging_ = final_ / temporaryPathFor(final_ / "out").filename();
    } else {
        const fs::path parent = final_.has_parent_path() ? final_.parent_path() : fs::path(".");
        fs::create_directories(parent, ec);
        if (ec)
            throw PathError("cannot create the folder " + parent.string() + ": " + ec.message(),
                            final_.string());
        staging_ = temporaryPathFor(final_);
    }
    if (!fs::create_directory(staging_, ec) || ec)
        throw PathError("cannot create the folder " + staging_.string() + ": " + ec.message(),
                        final_.string());
}

StagedOutputFolder::~StagedOutputFolder() {
    if (committed_) return;
    std::error_code ec;
    fs::remove_all(staging_, ec);
}

void StagedOutputFolder::commit() {
    std::error_code ec;
    if (!fs::exists(final_, ec)) {
        fs::rename(staging_, final_, ec);
    } else {
        for (const auto& entry : fs::directory_iterator(staging_, ec)) {
            fs::rename(entry.path(), final_ / entry.path().filename(), ec);
            if (ec) break;
        }
        if (!ec) fs::remove(staging_, ec);
    }
    if (ec)
        throw PathError("cannot move the output into " + final_.string() + ": " + ec.message(),
                        final_.string());
    committed_ = true;
}

}  // namespace kfd
