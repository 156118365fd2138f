#include "kfd/io/scan_csv.h"

#include <cmath>

#include "kfd/pipeline/format.h"

#include "kfd/io/source.h"

namespace kfd {
namespace {

// ",x,y,phi" of a pose (%.6f, any size), or ",,," when there is none.
void appendPose(std::string& line, const std::optional<Pose2D>& p) {
    line += p ? format(",%.6f,%.6f,%.6f", p->x, p->y, p->phi) : std::string(",,,");
}

// Runs fn; a failed write comes out as a ScanCsvError with the same message.
template <class Fn>
void asScanCsvError(Fn&& fn) {
    try {
        fn();
    } catch (const WriteError& e) {
        throw ScanCsvError(e.what(), e.field());
    }
}

// A CSV field (RFC 4180): quoted, its quotes doubled, when it holds a comma, a quote or a line
// break (a sensor label can hold anything); as it is otherwise.
std::string csvField(const std::string& s) {
    if (s.find_first_of(",\"\r\n") == std::string::npos) return s;
    std::string q = "\"";
    for (const char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
    return q + '"';
}

}  // namespace

void ScanCsvWriter::open(const std::string& path, const std::string& name,
                         const StageOutputs& stages) {
    stages_ = stages;
    asScanCsvError([&] {
        out_.emplace(path, name);
        std::string header =
            "index,timestamp,sensor,kept,reason,points_in,removed_noise,surface_m,points_out,"
            "microseconds";
        for (const std::string& c : stages_.columns()) header += "," + c;
        *out_ << header << ",icp_goodness,odom_x,odom_y,odom_phi,x,y,phi\n";
    });
}

void ScanCsvWriter::write(const ScanRecord& r, const std::optional<Pose2D>& pose) {
    std::string line =
        format("%zu,%.6f,%s,%d,%s,%zu,%zu,%.2f,%zu,%.2f", r.index, stampForOutput(r.stamp),
               csvField(r.sensor).c_str(), r.kept ? 1 : 0, r.reason, r.points_in, r.removed_noise,
               r.surface_m, r.points_out, r.microseconds);
    line += stages_.cells(r.report);
    line += std::isnan(r.icp_goodness)
                ? std::string(",")
                : format(",%.4f%s", r.icp_goodness, r.icp_rejected ? "r" : "");
    appendPose(line, r.odometry);
    appendPose(line, pose);
    line += '\n';
    asScanCsvError([&] { out_->write(line); });
}

void ScanCsvWriter::close() {
    if (out_) asScanCsvError([&] { out_->close(); });
}

}  // namespace kfd
