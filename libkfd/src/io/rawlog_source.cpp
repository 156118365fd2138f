#include "kfd/io/rawlog_source.h"

#include <mrpt/io/CStream.h>
#include <mrpt/serialization/CArchive.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <vector>

#include "gz_reader.h"
#include "kfd/mrpt/allocation_limit.h"

namespace kfd {
namespace {

namespace fs = std::filesystem;
using detail::GzReader;

// MRPT's exception banner as its message (kfd::plainMessage), on one line.
std::string lastMessage(const std::string& what) {
    const std::string m = plainMessage(what);
    return m.substr(0, m.find('\n'));
}

}  // namespace

struct RawlogSource::Impl {
    std::string path;
    GzReader in;
    mrpt::serialization::CArchiveStreamBase<mrpt::io::CStream> arch{in};
    OdometryTracker odometry;
    mrpt::serialization::CSerializable::Ptr lookahead;  // read after a lone action
    bool ended = false;
    std::size_t objects = 0, entries = 0;

    explicit Impl(const std::string& p) : path(p), in(p) {}

    // The next object, or nullptr at a clean end of file. Null objects stored in the file are
    // skipped (and not counted).
    mrpt::serialization::CSerializable::Ptr read() {
        if (lookahead) return std::move(lookahead);
        mrpt::serialization::CSerializable::Ptr obj;
        while (!obj && !ended) {
            try {
                // No allocation larger than the data left (allocation_limit.h).
                const ScopedAllocationLimit limit(static_cast<std::size_t>(std::min<std::uint64_t>(
                                                      bytesLeft(), SIZE_MAX - kAllocationSlack)) +
                                                  kAllocationSlack);
                obj = arch.ReadObject();
            } catch (const mrpt::serialization::CExceptionEOF&) {
                ended = true;
                if (const std::string f = in.failure(); !f.empty()) throw error(f);
            } catch (const std::bad_alloc&) {
                ended = true;
                throw corruptLength();
            } catch (const std::exception& e) {
                ended = true;
                if (!in.error().empty()) throw error(in.error());  // the gzip layer knows why
                // OpenCV's images allocate with malloc, outside the limit: an impossible size
                // comes back as OpenCV's out-of-memory error (fuzz_rawlog's finding).
                const std::string what = e.what();
                if (what.find("Insufficient memory") != std::string::npos ||
                    what.find("Failed to allocate") != std::string::npos)
                    throw corruptLength();
                throw error(lastMessage(what));
            }
        }
        if (obj) ++objects;
        return obj;
    }

    // Decoded bytes not read yet.
    std::uint64_t bytesLeft() const {
        return in.getTotalBytesCount() - std::min(in.getPosition(), in.getTotalBytesCount());
    }

    RawlogError corruptLength() const {
        return error("an object claims more memory than the " + std::to_string(bytesLeft()) +
                         " bytes left in the file (a corrupt length field)",
                     true);
    }

    // `said`: `what` says itself that the file is corrupt (no hint added).
    RawlogError error(const std::string& what, bool said = false) const {
        const char* hint = said           ? ": "
                           : objects == 0 ? " (is it an MRPT rawlog?): "
                                          : " (truncated or corrupt file?): ";
        return RawlogError(
            "cannot read object #" + std::to_string(objects) + " of " + path + hint + what, path);
    }
};

namespace {
// Decodes the whole file once; returns its decoded size, or throws RawlogError naming the
// file and the reason.
std::uint64_t decodeAll(const std::string& path) {
    GzReader in(path);
    if (!in.isOpen()) throw RawlogError("cannot open " + path, path);
    std::vector<char> buf(1 << 16);
    std::uint64_t total = 0;
    while (const std::size_t n = in.Read(buf.data(), buf.size())) total += n;
    if (const std::string f = in.failure(); !f.empty())
        throw RawlogError(path + ": " + f + " (truncated or corrupt file?)", path);
    return total;
}
}  // namespace

void checkGzipIntegrity(const std::string& path) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) throw RawlogError("file not found: " + path, path);
    decodeAll(path);
}

RawlogSource::RawlogSource(const std::string& path) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) throw RawlogError("input rawlog not found: " + path, path);
    impl_ = std::make_unique<Impl>(path);
    if (!impl_->in.isOpen()) throw RawlogError("cannot open the input rawlog: " + path, path);
    if (impl_->in.getTotalBytesCount() == 0) throw RawlogError("the input is empty: " + path, path);
    // A gzip file is decoded once before any object is read: damaged compressed data decodes
    // to garbage whose length fields MRPT's deserialisers trust (a 12 kB file found by
    // fuzz_rawlog made them allocate 2.7 GB), and a cut or corrupt file then fails before
    // anything is written. It also gives the decoded size, which bytesRead() counts in.
    if (impl_->in.isGzip()) impl_->in.setTotal(decodeAll(path));
}

RawlogSource::~RawlogSource() = default;

bool RawlogSource::next(SourceEntry& e) {
    using mrpt::obs::CActionCollection;
    using mrpt::obs::CObservation;
    using mrpt::obs::CSensoryFrame;
    Impl& m = *impl_;
    auto obj = m.read();
    if (!obj) return false;
    e = SourceEntry();
    if (auto acts = std::dynamic_pointer_cast<CActionCollection>(obj)) {
        e.action = acts;
        m.odometry.onAction(*acts);
        auto following = m.read();
        if (auto sf = std::dynamic_pointer_cast<CSensoryFrame>(following)) {
            e.kind = SourceEntry::Kind::Frame;
            e.frame = sf;
        } else {
            e.kind = SourceEntry::Kind::Action;
            m.lookahead = std::move(following);
        }
    } else if (auto sf = std::dynamic_pointer_cast<CSensoryFrame>(obj)) {
        e.kind = SourceEntry::Kind::Frame;
        e.frame = sf;
    } else if (auto o = std::dynamic_pointer_cast<CObservation>(obj)) {
        e.kind = SourceEntry::Kind::Observation;
        e.observation = o;
        m.odometry.onObservation(*o);
    } else {
        e.kind = SourceEntry::Kind::Other;
        e.other = std::move(obj);
    }
    e.odometry = m.odometry.current();
    e.index = m.entries++;
    e.objects_read = m.objects - (m.lookahead ? 1 : 0);
    // A laser mount (sensor pose) that is not finite would put every point of the scan nowhere.
    e.forEachScan([&](const mrpt::obs::CObservation2DRangeScan::Ptr& s) {
        const auto& p = s->sensorPose;
        if (std::isfinite(p.x()) && std::isfinite(p.y()) && std::isfinite(p.z()) &&
            std::isfinite(p.yaw()) && std::isfinite(p.pitch()) && std::isfinite(p.roll()))
            return;
        char buf[160];
        std::snprintf(buf, sizeof(buf), "(x %g, y %g, z %g m, yaw %g, pitch %g, roll %g rad)",
                      p.x(), p.y(), p.z(), p.yaw(), p.pitch(), p.roll());
        throw RawlogError(m.path + ": object #" + std::to_string(e.objects_read - 1) +
                              ": the laser mount (sensor pose) of scan '" + s->sensorLabel +
                              "' is not finite " + buf,
                          m.path);
    });
    return true;
}

const std::string& RawlogSource::path() const { return impl_->path; }
std::uint64_t RawlogSource::bytesRead() const { return impl_->in.getPosition(); }
std::uint64_t RawlogSource::bytesTotal() const { return impl_->in.getTotalBytesCount(); }

}  // namespace kfd
