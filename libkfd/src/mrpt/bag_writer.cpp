#include "kfd/mrpt/bag_writer.h"

#include <rosbag/bag.h>
#include <sensor_msgs/LaserScan.h>

#include <algorithm>
#include <limits>

#include "bag_message.h"

namespace kfd {

const char* toString(RemovedMark m) { return m == RemovedMark::NaN ? "nan" : "inf"; }

RemovedMark parseRemovedMark(const std::string& text) {
    if (text == "nan") return RemovedMark::NaN;
    if (text == "inf") return RemovedMark::PlusInf;
    throw Error("'" + text + "' is not a removed-point mark (nan or inf)");
}

struct BagWriter::Impl {
    std::string path;
    rosbag::Bag bag;
    BagWriterOptions options;
    std::size_t written = 0;
    bool open = false;

    template <class Fn>
    void guarded(Fn&& fn, const char* what) {
        try {
            fn();
        } catch (const std::exception& e) {
            throw BagError(path + ": " + what + " (" + e.what() + ")", path);
        }
    }
};

BagWriter::BagWriter(const std::string& path, const BagWriterOptions& options)
    : impl_(std::make_unique<Impl>()) {
    Impl& d = *impl_;
    d.path = path;
    d.options = options;
    d.guarded(
        [&] {
            d.bag.open(path, rosbag::bagmode::Write);
            switch (options.compression) {
                case BagWriterOptions::Compression::None:
                    d.bag.setCompression(rosbag::compression::Uncompressed);
                    break;
                case BagWriterOptions::Compression::Lz4:
                    d.bag.setCompression(rosbag::compression::LZ4);
                    break;
                case BagWriterOptions::Compression::Bz2:
                    d.bag.setCompression(rosbag::compression::BZ2);
                    break;
            }
        },
        "cannot create the bag");
    d.open = true;
}

BagWriter::~BagWriter() {
    if (impl_->open) try {
            impl_->bag.close();
        } catch (...) {  // the file is discarded by the caller (a temporary) anyway
        }
}

void BagWriter::copy(const NativeMessage& message) {
    const auto& m = message.message;
    impl_->guarded([&] { impl_->bag.write(m.getTopic(), m.getTime(), m, m.getConnectionHeader()); },
                   "failed writing a message");
    ++impl_->written;
}

std::size_t BagWriter::writeScan(const NativeMessage& original,
                                 const mrpt::obs::CObservation2DRangeScan& cleaned) {
    const auto& m = original.message;
    auto ls = m.instantiate<sensor_msgs::LaserScan>();  // its bytes checked when read
    if (!ls)
        throw BagError(impl_->path + ": the message on " + m.getTopic() + " is not a LaserScan");
    const float mark = impl_->options.removed == RemovedMark::NaN
                           ? std::numeric_limits<float>::quiet_NaN()
                           : std::numeric_limits<float>::infinity();
    std::size_t marked = 0;
    const std::size_t n = std::min(ls->ranges.size(), cleaned.getScanSize());
    for (std::size_t i = 0; i < n; ++i) {
        if (validRange(*ls, ls->ranges[i]) && !cleaned.getScanRangeValidity(i)) {
            ls->ranges[i] = mark;
            ++marked;
        }
    }
    impl_->guarded(
        [&] { impl_->bag.write(m.getTopic(), m.getTime(), *ls, m.getConnectionHeader()); },
        "failed writing a scan");
    ++impl_->written;
    return marked;
}

void BagWriter::close() {
    impl_->guarded([&] { impl_->bag.close(); }, "failed writing the bag's index");
    impl_->open = false;
}

std::size_t BagWriter::messagesWritten() const { return impl_->written; }

}  // namespace kfd
