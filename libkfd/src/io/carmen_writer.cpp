#include "kfd/io/carmen_writer.h"

#include <mrpt/poses/CPose2D.h>
#include <mrpt/poses/CPose3D.h>

#include <array>
#include <charconv>
#include <cmath>
#include <optional>
#include <vector>

#include "kfd/io/gz_output.h"
#include "kfd/io/source.h"  // stampOf
#include "kfd/os/output_paths.h"

namespace kfd {
namespace {

// The shortest text that reads back as the same value (std::to_chars).
template <class T>
void appendNumber(std::string& out, T v) {
    std::array<char, 32> buf{};
    const auto r = std::to_chars(buf.data(), buf.data() + buf.size(), v);
    out.append(buf.data(), r.ptr);
}

// What PARAM lines last said for one laser (FLASER or RLASER).
struct Laser {
    std::string label;  // the scans' sensorLabel
    const char* keyword = "FLASER";
    const char* max_param = "robot_front_laser_max";
    const char* res_param = "laser_front_laser_resolution";
    std::optional<double> max_range, resolution_deg;
};

}  // namespace

bool isCarmenOutputName(const std::string& path) {
    for (const char* ext : {".clf", ".log", ".clf.gz", ".log.gz"})
        if (hasExtension(path, ext)) return true;
    return false;
}

struct CarmenWriter::Impl {
    std::optional<OutputFile> plain;
    std::optional<GzOutputStream> gz;
    std::string name;
    std::vector<Laser> lasers;
    std::string line;
    std::size_t lines = 0;

    void put(const std::string& text) {
        if (gz)
            gz->Write(text.data(), text.size());
        else
            plain->write(text);
        ++lines;
    }

    Laser& laserFor(const std::string& label) {
        for (auto& l : lasers)
            if (l.label == label) return l;
        if (lasers.size() == 2)
            throw CarmenWriteError(
                "a CARMEN log holds two lasers (FLASER, RLASER): the scans of '" + label +
                    "' are a third (" + lasers[0].label + ", " + lasers[1].label +
                    "); write a .rawlog instead",
                name);
        Laser l;
        l.label = label;
        if (!lasers.empty()) {
            l.keyword = "RLASER";
            l.max_param = "robot_rear_laser_max";
            l.res_param = "laser_rear_laser_resolution";
        }
        lasers.push_back(l);
        return lasers.back();
    }

    void param(const char* key, double value) {
        line = "PARAM ";
        line += key;
        line += ' ';
        appendNumber(line, value);
        line += '\n';
        put(line);
    }

    // " t kfd t\n": the ipc timestamp, the host name and the logger timestamp.
    void tail(double stamp) {
        const double t = stampForOutput(stamp);
        line += ' ';
        appendNumber(line, t);
        line += " kfd ";
        appendNumber(line, t);
        line += '\n';
    }
};

CarmenWriter::CarmenWriter(const std::filesystem::path& path, const std::string& name, bool gzip,
                           int level, const std::string& origin)
    : impl_(std::make_unique<Impl>()) {
    Impl& d = *impl_;
    d.name = name.empty() ? path.string() : name;
    if (gzip)
        d.gz.emplace(path, d.name, level);
    else
        d.plain.emplace(path, d.name);
    std::string head =
        "# CARMEN log written by kfd\n"
        "# FLASER/RLASER num_readings [range_readings] x y theta odom_x odom_y odom_theta "
        "ipc_timestamp ipc_hostname logger_timestamp\n"
        "# ODOM x y theta tv rv accel ipc_timestamp ipc_hostname logger_timestamp\n"
        "# invalid and removed beams: 0 (no reading), or the max range when beyond it\n";
    if (!origin.empty()) head += "# " + origin + "\n";
    d.put(head);
    d.lines = 0;  // linesWritten(): the data lines
}

CarmenWriter::~CarmenWriter() = default;

void CarmenWriter::writeOdometry(const Pose2D& o, double stamp) {
    Impl& d = *impl_;
    d.line = "ODOM ";
    for (const double v : {o.x, o.y, o.phi}) {
        appendNumber(d.line, v);
        d.line += ' ';
    }
    d.line += "0 0 0";
    d.tail(stamp);
    d.put(d.line);
}

void CarmenWriter::writeScan(const mrpt::obs::CObservation2DRangeScan& scan, const Pose2D& o) {
    Impl& d = *impl_;
    Laser& laser = d.laserFor(scan.sensorLabel);
    const std::size_t n = scan.getScanSize();
    const double max_range = scan.maxRange;
    const double res_deg =
        n ? static_cast<double>(scan.aperture) * 180.0 / kPi / static_cast<double>(n) : 0.0;
    if (laser.max_range != max_range) d.param(laser.max_param, max_range);
    if (laser.resolution_deg != res_deg) d.param(laser.res_param, res_deg);
    laser.max_range = max_range;
    laser.resolution_deg = res_deg;

    d.line = laser.keyword;
    d.line += ' ';
    appendNumber(d.line, n);
    for (std::size_t k = 0; k < n; ++k) {
        const std::size_t i = scan.rightToLeft ? k : n - 1 - k;
        const float r = scan.getScanRange(i);
        d.line += ' ';
        if (scan.getScanRangeValidity(i))
            appendNumber(d.line, r);
        else if (r >= scan.maxRange)  // "no return": kept, as the max range (inf included)
            appendNumber(d.line, scan.maxRange);
        else
            d.line += '0';
    }
    const mrpt::poses::CPose2D odo(o.x, o.y, o.phi);
    const mrpt::poses::CPose2D laser_pose = odo + mrpt::poses::CPose2D(scan.sensorPose);
    for (const double v : {laser_pose.x(), laser_pose.y(), laser_pose.phi(), o.x, o.y, o.phi}) {
        d.line += ' ';
        appendNumber(d.line, v);
    }
    d.tail(stampOf(scan));
    d.put(d.line);
}

void CarmenWriter::close() {
    Impl& d = *impl_;
    if (d.gz)
        d.gz->close();
    else
        d.plain->close();
}

std::size_t CarmenWriter::linesWritten() const { return impl_->lines; }

}  // namespace kfd
