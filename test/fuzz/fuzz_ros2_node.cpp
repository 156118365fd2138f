// libFuzzer target: the ROS 2 node's callbacks (kfd::ros2::Ros2Node, what DDS delivers to
// kfd_ros2) fed arbitrary messages. The input is a sequence of records [kind u8][size u16 LE]
// [bytes]: kind % 6 = 0 scan, 1 odometry, 2 tf, 3 tf_static, 4 the clock moves 0.3 s and the
// node ticks, 5 diagnostics. Each input gets a fresh node (odometry from tf, 0.5 s wait, queue
// 4) and ends with finish(). Whatever the bytes, nothing may crash, leak or hang.
#include <cstddef>
#include <cstdint>

#include "kfd/mrpt/config.h"
#include "kfd/ros2/ros2_node.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    kfd::ros2::Ros2Config c;
    c.pipeline = kfd::kfdDefaults();
    c.tf_wait = 0.5;
    c.queue_size = 4;
    double clock = 0.0;
    kfd::ros2::Ros2Outputs out;
    std::size_t published = 0;
    out.scan_filtered = [&](const kfd::ros2::Bytes& b) { published += b.size(); };
    out.track = out.scan_filtered;
    out.diagnostics = out.scan_filtered;
    kfd::ros2::Ros2Node node(c, out, [&] { return clock; });
    std::size_t at = 0;
    while (at + 3 <= size) {
        const unsigned kind = data[at] % 6;
        const std::size_t n =
            std::min<std::size_t>(data[at + 1] | (data[at + 2] << 8), size - at - 3);
        const std::uint8_t* msg = data + at + 3;
        at += 3 + n;
        switch (kind) {
            case 0:
                node.onScan(msg, n);
                break;
            case 1:
                node.onOdometry(msg, n);
                break;
            case 2:
                node.onTf(msg, n, false);
                break;
            case 3:
                node.onTf(msg, n, true);
                break;
            case 4:
                clock += 0.3;
                node.tick();
                break;
            default:
                node.publishDiagnostics(clock);
                break;
        }
    }
    node.finish();
    return published == static_cast<std::size_t>(-1);  // keeps `published` observable
}
