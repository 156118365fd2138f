#include <kfd/mrpt/stream_filter.h>
#include <kfd/paper/window_helper.h>

int main() {
    kfd::StreamFilter filter;
    const auto s = kfd::suggestWindow(0.752, 40.0, 0.985);
    return (filter.sensorCount() == 0 && s.m_max == 8) ? 0 : 1;
}
