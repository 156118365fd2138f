#include "kfd/io/bag_writer.h"

#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/LaserScan.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <limits>
#include <memory>
#include <vector>

#include "bag_message.h"

namespace kfd {

const char* toString(RemovedMark m) { return m == RemovedMark::NaN ? "nan" : "inf"; }

RemovedMark parseRemovedMark(const std::string& text) {
    if (text == "nan") return RemovedMark::NaN;
    if (text == "inf") return RemovedMark::PlusInf;
    throw Error("'" + text + "' is not a removed-point mark (nan or inf)");
}

BagWriterOptions::Compression parseBagCompression(const std::string& text) {
    using C = BagWriterOptions::Compression;
    if (text == "input") return C::AsInput;
    if (text == "none") return C::None;
    if (text == "lz4") return C::Lz4;
    if (text == "bz2") return C::Bz2;
    if (text == "zstd") return C::Zstd;
    throw Error("'" + text + "' is not a bag compression (input, none, lz4, bz2 or zstd)");
}

const char* toString(BagWriterOptions::Compression c) {
    switch (c) {
        case BagWriterOptions::Compression::AsInput:
            return "input";
        case BagWriterOptions::Compression::None:
            return "none";
        case BagWriterOptions::Compression::Lz4:
            return "lz4";
        case BagWriterOptions::Compression::Bz2:
            return "bz2";
        case BagWriterOptions::Compression::Zstd:
            return "zstd";
    }
    return "none";
}

namespace {

// A rosbag::Bag whose write failed cannot be destroyed: its destructor closes it, closing writes
// the index, the write fails again and the exception leaves a destructor (std::terminate: a full
// disk aborted kfd-filter). Such a bag is set aside here, reachable and never destroyed (its
// temporary file is removed by its owner; the descriptor goes with the process).
void abandon(std::unique_ptr<rosbag::Bag> bag) {
    static auto* const abandoned = new std::vector<std::unique_ptr<rosbag::Bag>>;
    abandoned->push_back(std::move(bag));
}

}  // namespace

struct BagWriter::Impl {
    std::string path, name;  // the file written, the file users know
    std::unique_ptr<rosbag::Bag> bag = std::make_unique<rosbag::Bag>();  // null once failed
    BagWriterOptions options;
    std::size_t written = 0;

    // Runs fn on the bag; rosbag's exceptions (which say "Error writing to file", not why)
    // become a BagError "cannot write NAME: REASON (rosbag: what: its message)", REASON the
    // errno that rosbag's failing stdio call left, when there is one. A bag that failed is
    // abandoned, and every later call fails at once.
    template <class Fn>
    void guarded(Fn&& fn, const char* what) {
        if (!bag) throw BagError("cannot write " + name + ": an earlier write failed", name);
        errno = 0;
        try {
            fn(*bag);
        } catch (const std::exception& e) {
            const int err = errno;
            abandon(std::move(bag));
            throw BagError(
                "cannot write " + name + ": " +
                    (err ? std::string(std::strerror(err)) + " (rosbag: " : "(rosbag: ") + what +
                    ": " + e.what() + ")",
                name);
        }
    }
};

BagWriter::BagWriter(const std::string& path, const BagWriterOptions& options,
                     const std::string& name)
    : impl_(std::make_unique<Impl>()) {
    Impl& d = *impl_;
    d.path = path;
    d.name = name.empty() ? path : name;
    d.options = options;
    d.guarded(
        [&](rosbag::Bag& bag) {
            bag.open(path, rosbag::bagmode::Write);
            switch (options.compression) {
                case BagWriterOptions::Compression::AsInput:  // resolved by the caller
                case BagWriterOptions::Compression::None:
                    bag.setCompression(rosbag::compression::Uncompressed);
                    break;
                case BagWriterOptions::Compression::Lz4:
                    bag.setCompression(rosbag::compression::LZ4);
                    break;
                case BagWriterOptions::Compression::Bz2:
                    bag.setCompression(rosbag::compression::BZ2);
                    break;
                case BagWriterOptions::Compression::Zstd:
                    throw BagError("a ROS 1 bag has no zstd chunks (none, lz4 or bz2)");
            }
        },
        "cannot create the bag");
}

BagWriter::~BagWriter() {
    if (impl_->bag) try {  // not closed: the file is discarded by the caller (a temporary)
            impl_->bag->close();
        } catch (...) {
            abandon(std::move(impl_->bag));
        }
}

void BagWriter::copy(const NativeMessage& m) {
    impl_->guarded([&](rosbag::Bag& bag) { bag.write(m.topic(), m.time, m, m.connection->header); },
                   "failed writing a message");
    ++impl_->written;
}

std::size_t BagWriter::writeScan(const NativeMessage& original,
                                 const mrpt::obs::CObservation2DRangeScan& cleaned) {
    const NativeMessage& m = original;
    auto ls = m.instantiate<sensor_msgs::LaserScan>();  // its bytes checked when read
    if (!ls)
        throw BagError(impl_->name + ": the message on " + m.topic() + " is not a LaserScan",
                       impl_->name);
    const std::size_t marked = markRemovedBeams(*ls, cleaned, impl_->options.removed);
    impl_->guarded(
        [&](rosbag::Bag& bag) { bag.write(m.topic(), m.time, *ls, m.connection->header); },
        "failed writing a scan");
    ++impl_->written;
    return marked;
}

void BagWriter::close() {
    Impl& d = *impl_;
    d.guarded([&](rosbag::Bag& bag) { bag.close(); }, "failed writing the bag's index");
    // Read back: the index must open and count every message written.
    std::size_t indexed = 0;
    d.guarded(
        [&](rosbag::Bag&) {
            rosbag::Bag check(d.path, rosbag::bagmode::Read);
            indexed = rosbag::View(check).size();
        },
        "the written bag does not open");
    d.bag.reset();
    if (indexed != d.written)
        throw BagError("cannot write " + d.name + ": the written bag's index holds " +
                           std::to_string(indexed) + " messages, not the " +
                           std::to_string(d.written) + " written",
                       d.name);
}

std::size_t BagWriter::messagesWritten() const { return impl_->written; }

}  // namespace kfd
