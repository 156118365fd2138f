#include "kfd/os/output_paths.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstring>
#include <random>
#include <system_error>

namespace kfd {
namespace fs = std::filesystem;

namespace {

std::string reason(int err) { return std::strerror(err); }

[[noreturn]] void throwWriteError(const std::string& name, const std::string& why) {
    throw WriteError("cannot write " + name + ": " + why, name);
}

// What a file that is not a regular one is, in words.
const char* kindOf(fs::file_type t) {
    switch (t) {
        case fs::file_type::directory:
            return "a folder";
        case fs::file_type::character:
            return "a character device";
        case fs::file_type::block:
            return "a block device";
        case fs::file_type::fifo:
            return "a FIFO";
        case fs::file_type::socket:
            return "a socket";
        default:
            return "not a regular file";
    }
}

// write(2) of the whole buffer, retried on EINTR and short writes; 0 or the errno.
int writeAll(int fd, const char* data, std::size_t n) {
    while (n > 0) {
        const ssize_t w = ::write(fd, data, n);
        if (w < 0) {
            if (errno == EINTR) continue;
            return errno;
        }
        if (w == 0) return EIO;
        data += w;
        n -= static_cast<std::size_t>(w);
    }
    return 0;
}

// Opens `path` (no symlink followed, never blocking on a FIFO) and takes an exclusive flock
// without waiting; -1 when it cannot (held by a live process, or no locks on this file system).
int lockIfFree(const fs::path& path, bool dir) {
    const int fd = ::open(path.c_str(),
                          O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC | (dir ? O_DIRECTORY : 0));
    if (fd < 0) return -1;
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
        ::close(fd);
        return -1;
    }
    return fd;
}

// True when `fd` is the file now named `path` (not unlinked or replaced meanwhile).
bool sameInode(int fd, const fs::path& path) {
    struct stat a {
    }, b{};
    return ::fstat(fd, &a) == 0 && ::lstat(path.c_str(), &b) == 0 && a.st_dev == b.st_dev &&
           a.st_ino == b.st_ino;
}

// Creates a fresh temporary beside `final_path` (a file, or a folder when `dir`), exclusively,
// and locks it. Returns the locked descriptor (or -1 on a file system without locks) and sets
// `temp`. A temporary removed by another run's removeStaleTemporaries between its creation and
// its lock is created again under another name.
int createLockedTemporary(const fs::path& final_path, bool dir, fs::path& temp,
                          const std::string& name) {
    for (int attempt = 0; attempt < 100; ++attempt) {
        temp = temporaryPathFor(final_path);
        int fd = -1;
        if (dir) {
            if (::mkdir(temp.c_str(), 0777) == 0)
                fd = ::open(temp.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
            else if (errno != EEXIST)
                throw PathError("cannot create the folder " + temp.string() + ": " + reason(errno),
                                name);
        } else {
            fd = ::open(temp.c_str(), O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
            if (fd < 0 && errno != EEXIST) throwWriteError(name, reason(errno));
        }
        if (fd < 0) continue;  // taken, or removed at once by a stale-temporary sweep
        if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
            const int err = errno;
            ::close(fd);
            if (err == EWOULDBLOCK) continue;  // a sweep holds it and removes it: another name
            return -1;  // no locks here (ENOLCK, EOPNOTSUPP): a sweep cannot lock it either
        }
        if (sameInode(fd, temp)) return fd;
        ::close(fd);  // removed (and maybe created again) between creation and lock
    }
    throw PathError("cannot find a free temporary name beside " + final_path.string(), name);
}

void releaseLock(int& fd) {
    if (fd >= 0) ::close(fd);
    fd = -1;
}

}  // namespace

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

void checkRegularOutput(const NamedPath& output) {
    if (output.path.empty()) return;
    std::error_code ec;
    const fs::file_status st = fs::status(output.path, ec);  // symlinks followed
    if (ec || !fs::exists(st) || fs::is_regular_file(st)) return;
    throw PathError("the " + output.role + " " + output.path + " is " + kindOf(st.type()) +
                        ", not a regular file: refusing to replace it",
                    output.path);
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
        checkRegularOutput(o);
    }
}

// --- OutputFile --------------------------------------------------------------------------

namespace {
constexpr std::size_t kBufferSize = 1 << 16;
constexpr std::size_t kTailSize = 16;
}  // namespace

OutputFile::OutputFile(const fs::path& path, std::string name) : name_(std::move(name)) {
    fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (fd_ < 0) fail(reason(errno));
    buffer_.reserve(kBufferSize);
}

OutputFile::~OutputFile() {
    if (fd_ >= 0) ::close(fd_);
}

void OutputFile::fail(const std::string& why) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
    throwWriteError(name_, why);
}

void OutputFile::flush() {
    if (buffer_.empty()) return;
    if (const int err = writeAll(fd_, buffer_.data(), buffer_.size())) fail(reason(err));
    flushed_ += buffer_.size();
    tail_ += buffer_.size() > kTailSize ? buffer_.substr(buffer_.size() - kTailSize) : buffer_;
    if (tail_.size() > kTailSize) tail_.erase(0, tail_.size() - kTailSize);
    buffer_.clear();
}

void OutputFile::write(const void* data, std::size_t size) {
    if (fd_ < 0) throwWriteError(name_, "the file is already closed");
    const char* p = static_cast<const char*>(data);
    size_ += size;
    if (buffer_.size() + size > kBufferSize) flush();
    if (size >= kBufferSize) {  // large: straight through
        if (const int err = writeAll(fd_, p, size)) fail(reason(err));
        flushed_ += size;
        tail_.assign(p + size - kTailSize, kTailSize);
        return;
    }
    buffer_.append(p, size);
}

void OutputFile::close() {
    if (fd_ < 0) return;
    flush();
    // Data the kernel could not place yet (delayed allocation, NFS) fails here.
    if (::fsync(fd_) != 0) fail(reason(errno));
    struct stat st {};
    if (::fstat(fd_, &st) != 0) fail(reason(errno));
    if (static_cast<std::uint64_t>(st.st_size) != flushed_)
        fail("the file holds " + std::to_string(st.st_size) + " bytes, not the " +
             std::to_string(flushed_) + " written");
    if (!tail_.empty()) {  // the last bytes, read back
        std::string back(tail_.size(), '\0');
        const ssize_t n =
            ::pread(fd_, back.data(), back.size(), static_cast<off_t>(flushed_ - tail_.size()));
        if (n < 0) fail(reason(errno));
        if (static_cast<std::size_t>(n) != back.size() || back != tail_)
            fail("the file does not end with the bytes written");
    }
    const int fd = fd_;
    fd_ = -1;
    if (::close(fd) != 0) throwWriteError(name_, reason(errno));
}

void syncAndCheckFile(const fs::path& path, const std::string& name) {
    const int fd = ::open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) throwWriteError(name, reason(errno));
    struct stat st {};
    std::string why;
    if (::fstat(fd, &st) != 0)
        why = reason(errno);
    else if (!S_ISREG(st.st_mode))
        why = "the written file is not a regular file";
    else if (st.st_size == 0)
        why = "the written file is empty";
    else if (::fsync(fd) != 0)
        why = reason(errno);
    const int closed = ::close(fd);
    if (why.empty() && closed != 0) why = reason(errno);
    if (!why.empty()) throwWriteError(name, why);
}

// --- temporary names -------------------------------------------------------------------------

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

std::size_t removeStaleTemporaries(const fs::path& final_path) {
    const fs::path dir = final_path.has_parent_path() ? final_path.parent_path() : fs::path(".");
    const std::string prefix = "." + final_path.stem().string() + ".kfd-tmp-",
                      ext = final_path.extension().string();
    std::size_t removed = 0;
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(dir, ec)) {
        // Exactly the names temporaryPathFor gives: prefix, 1 to 6 digits, the extension.
        const std::string n = entry.path().filename().string();
        if (n.size() <= prefix.size() + ext.size() || n.compare(0, prefix.size(), prefix) != 0 ||
            n.compare(n.size() - ext.size(), ext.size(), ext) != 0)
            continue;
        const std::string digits = n.substr(prefix.size(), n.size() - prefix.size() - ext.size());
        if (digits.size() > 6 || digits.find_first_not_of("0123456789") != std::string::npos)
            continue;
        struct stat st {};
        if (::lstat(entry.path().c_str(), &st) != 0 || st.st_uid != ::geteuid()) continue;
        const bool dir_entry = S_ISDIR(st.st_mode);
        if (!dir_entry && !S_ISREG(st.st_mode)) continue;
        const int fd = lockIfFree(entry.path(), dir_entry);
        if (fd < 0) continue;  // a live run holds it, or no locks here
        std::error_code rm;
        if (sameInode(fd, entry.path())) {
            if (dir_entry)
                fs::remove_all(entry.path(), rm);
            else
                fs::remove(entry.path(), rm);
            if (!rm) ++removed;
        }
        ::close(fd);
    }
    return removed;
}

// --- TempOutputFile ---------------------------------------------------------------------------

TempOutputFile::TempOutputFile(fs::path final_path) : final_(std::move(final_path)) {
    checkRegularOutput({"output", final_.string()});
    if (final_.has_parent_path()) {  // "out/x.png" in a fresh clone: out/ is made, as for folders
        std::error_code ec;
        fs::create_directories(final_.parent_path(), ec);
        if (ec)
            throw WriteError("cannot write " + final_.string() + ": cannot create the folder " +
                                 final_.parent_path().string() + ": " + ec.message(),
                             final_.string());
    }
    removeStaleTemporaries(final_);
    lock_ = createLockedTemporary(final_, false, temp_, final_.string());
}

TempOutputFile::~TempOutputFile() {
    if (!committed_) {
        std::error_code ec;
        fs::remove(temp_, ec);
    }
    releaseLock(lock_);
}

void TempOutputFile::commit() {
    syncAndCheckFile(temp_, final_.string());
    std::error_code ec;
    fs::rename(temp_, final_, ec);
    if (ec)
        throw PathError(
            "cannot move " + temp_.string() + " to " + final_.string() + ": " + ec.message(),
            final_.string());
    committed_ = true;
    releaseLock(lock_);
}

// --- StagedOutputFolder -----------------------------------------------------------------------

StagedOutputFolder::StagedOutputFolder(fs::path final_dir) : final_(std::move(final_dir)) {
    std::error_code ec;
    if (final_.filename().empty()) final_ = final_.parent_path();  // "out/" -> "out"
    const auto st = fs::status(final_, ec);
    if (fs::exists(st) && !fs::is_directory(st))
        throw PathError("the output folder " + final_.string() + " is not a folder",
                        final_.string());
    if (fs::is_directory(st)) {
        removeStaleTemporaries(final_ / "out");  // an earlier run's stage inside it
        removeStaleTemporaries(final_);          // or beside it (the folder was new then)
        lock_ = createLockedTemporary(final_ / "out", true, staging_, final_.string());
    } else {
        const fs::path parent = final_.has_parent_path() ? final_.parent_path() : fs::path(".");
        fs::create_directories(parent, ec);
        if (ec)
            throw PathError("cannot create the folder " + parent.string() + ": " + ec.message(),
                            final_.string());
        removeStaleTemporaries(final_);
        lock_ = createLockedTemporary(final_, true, staging_, final_.string());
    }
}

StagedOutputFolder::~StagedOutputFolder() {
    if (!committed_) {
        std::error_code ec;
        fs::remove_all(staging_, ec);
    }
    releaseLock(lock_);
}

void StagedOutputFolder::commit() {
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(staging_, ec))
        syncAndCheckFile(entry.path(), finalName(entry.path().filename().string()));
    if (ec)
        throw PathError("cannot read the folder " + staging_.string() + ": " + ec.message(),
                        final_.string());
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
    releaseLock(lock_);
}

bool hasExtension(const std::string& path, const std::string& extension) {
    if (path.size() <= extension.size()) return false;
    for (std::size_t i = 0; i < extension.size(); ++i)
        if (std::tolower(static_cast<unsigned char>(path[path.size() - extension.size() + i])) !=
            std::tolower(static_cast<unsigned char>(extension[i])))
            return false;
    return true;
}

void checkOutputName(const NamedPath& output, const std::vector<std::string>& extensions,
                     const std::string& formats) {
    for (const auto& x : extensions)
        if (hasExtension(output.path, x)) return;
    throw PathError(
        "the " + output.role + " " + output.path + ": " + formats + "; its name says none of them",
        output.path);
}

}  // namespace kfd
