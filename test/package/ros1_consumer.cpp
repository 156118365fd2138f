// kfd::ros1 from the installed package (find_package(kfd COMPONENTS ros1)): the node's latency
// figures, a class of the library the node and nodelet wrap.
#include <kfd/live/latency_stats.h>

int main() {
    kfd::live::LatencyStats stats(4);
    for (const double us : {10.0, 20.0, 30.0, 40.0}) stats.add(us);
    return (stats.count() == 4 && stats.max() == 40.0) ? 0 : 1;
}
