#include "kfd/io/carmen_source.h"

#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/poses/CPose2D.h>
#include <mrpt/poses/CPose3D.h>

#include <charconv>
#include <cmath>
#include <deque>
#include <map>
#include <string_view>
#include <vector>

#include "gz_reader.h"
#include "kfd/pipeline/format.h"
#include "kfd/pipeline/scan.h"

namespace kfd {
namespace {

using mrpt::obs::CObservation2DRangeScan;
using mrpt::obs::CObservationOdometry;
using mrpt::poses::CPose2D;
constexpr double kDeg = kPi / 180.0;
// Bounds on one line, so that no input makes the reader hold more than ~100 MB: a RAWLASER
// line of the largest counts (1e6 readings and 1e6 remissions, below) has 2 000 024 fields of
// at most ~20 characters.
constexpr std::size_t kMaxLine = std::size_t{64} << 20;  // bytes
constexpr std::size_t kMaxFields = 2'000'100;
constexpr double kMaxCount = 1e6;  // readings or remissions of one line

// Reads a (plain or gzip) file line by line through detail::GzReader.
class LineReader {
  public:
    /// CarmenError when `path` is not a readable file.
    explicit LineReader(const std::string& path) : in_(path), path_(path) {
        std::error_code ec;
        if (!std::filesystem::is_regular_file(path, ec) || !in_.isOpen())
            throw CarmenError(path + ": cannot open the CARMEN log", path);
    }
    // The next line without its end of line; false at the end of the file. Throws CarmenError
    // when the stream is broken (a cut or corrupt gzip).
    bool next(std::string& line) {
        line.clear();
        bytes_ = 0;
        for (;;) {
            if (pos_ == len_) {
                if (eof_) break;
                len_ = in_.Read(buf_.data(), buf_.size());
                pos_ = 0;
                if (len_ == 0) {
                    eof_ = true;
                    if (const std::string f = in_.failure(); !f.empty())
                        throw CarmenError(
                            path_ + ": " + f + " (after line " + std::to_string(number_) + ")",
                            path_);
                    break;
                }
            }
            const char* b = buf_.data() + pos_;
            const void* nl = std::memchr(b, '\n', len_ - pos_);
            const std::size_t n =
                nl ? static_cast<std::size_t>(static_cast<const char*>(nl) - b) : len_ - pos_;
            if (line.size() + n > kMaxLine)
                throw CarmenError(path_ + ":" + std::to_string(number_ + 1) +
                                      ": a line longer than " + std::to_string(kMaxLine >> 20) +
                                      " MiB (not a CARMEN log?)",
                                  path_);
            line.append(b, n);
            pos_ += n;
            bytes_ += n;
            if (nl) {
                ++pos_;
                ++bytes_;
                ++number_;
                if (!line.empty() && line.back() == '\r') line.pop_back();
                return true;
            }
        }
        if (line.empty()) return false;
        ++number_;  // a last line without '\n'
        return true;
    }
    std::size_t number() const { return number_; }
    /// The bytes of the last line in the file, its line end included.
    std::size_t bytes() const { return bytes_; }
    std::uint64_t position() const { return in_.getPosition(); }
    std::uint64_t total() const { return in_.getTotalBytesCount(); }

  private:
    detail::GzReader in_;
    std::string path_;
    std::array<char, 1 << 16> buf_{};
    std::size_t pos_ = 0, len_ = 0, number_ = 0, bytes_ = 0;
    bool eof_ = false;
};

// The line's fields into `t`; false (t cut there) when it has more than kMaxFields.
bool tokenize(const std::string& line, std::vector<std::string_view>& t) {
    t.clear();
    std::size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
        const std::size_t b = i;
        while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i]))) ++i;
        if (i > b) {
            if (t.size() == kMaxFields) return false;
            t.emplace_back(line.data() + b, i - b);
        }
    }
    return true;
}

// The laser of FLASER (front) or RLASER (rear) lines: its PARAMs.
struct LaserParams {
    double max_range = 81.0;      // robot_*_laser_max
    double resolution_deg = 0.0;  // laser_*_laser_resolution; 0 = not given (defaultResolution)
    bool offset_given = false;    // robot_*laser_offset and friends
    double offset_x = 0.0, offset_side = 0.0, offset_angle = 0.0;
};

// A FLASER line covers 180 degrees (CARMEN's convention). Without a resolution PARAM: the SICK
// resolution (1, 0.5 or 0.25 deg) within 1 % of 180 / n, else 180 / n. For the 0.5 deg mode
// (361 beams) this is MRPT carmen2rawlog's fixed default of 0.5 deg; for 180 beams that
// default would give a 90 deg aperture, this gives 180.
double defaultResolution(std::size_t n) {
    const double r = 180.0 / static_cast<double>(std::max<std::size_t>(n, 1));
    for (const double sick : {1.0, 0.5, 0.25})
        if (std::fabs(r - sick) <= 0.01 * sick) return sick;
    return r;
}

// A CARMEN keyword: an upper-case letter, then upper-case letters, digits or '_' (FLASER,
// ROBOTLASER1, NMEAGGA, ...).
bool isKeyword(std::string_view w) {
    if (w.empty() || w[0] < 'A' || w[0] > 'Z') return false;
    for (const char c : w)
        if (!((c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_')) return false;
    return true;
}

// True for a line that is not CARMEN text (SourceCounters::lines_unparsable): a control
// character other than a tab anywhere, a byte above 127 outside a comment, or a first field
// that is not a keyword. `tok`: the line's fields (none for an empty line).
bool unparsable(const std::string& line, const std::vector<std::string_view>& tok) {
    const bool comment = !tok.empty() && tok[0].front() == '#';
    for (const char ch : line) {
        const auto c = static_cast<unsigned char>(ch);
        if ((c < 0x20 && c != '\t') || c == 0x7f || (c > 0x7f && !comment)) return true;
    }
    return !tok.empty() && !comment && !isKeyword(tok[0]);
}

}  // namespace

struct CarmenSource::Impl {
    std::string path;
    LineReader lines;
    std::deque<SourceEntry> ready;
    OdometryTracker tracker;
    LaserParams front, rear;
    std::size_t entries = 0;
    std::string line;
    std::vector<std::string_view> tok;
    SourceCounters counts;
    std::uint64_t bytes_parsed = 0;  // the bytes of every other line (line ends included)

    explicit Impl(const std::string& p) : path(p), lines(p) {}

    [[noreturn]] void fail(const std::string& what) const {
        throw CarmenError(path + ":" + std::to_string(lines.number()) + ": " + what, path);
    }

    double number(std::size_t i) const {
        double v = 0.0;
        const std::string_view t = tok[i];
        const char* b = t.data();
        if (!t.empty() && *b == '+') ++b;
        const auto r = std::from_chars(b, t.data() + t.size(), v);
        if (r.ec != std::errc() || r.ptr != t.data() + t.size())
            fail(std::string(tok[0]) + " field " + std::to_string(i) + " ('" + std::string(t) +
                 "') is not a number");
        return v;
    }

    // A count read from field i: checked against the fields after it on the line before
    // anything is sized by it.
    std::size_t count(std::size_t i, const char* what) const {
        const double v = number(i);
        if (!(v >= 0.0) || v != std::floor(v))
            fail(std::string(tok[0]) + " " + what + " ('" + std::string(tok[i]) +
                 "') is not a count");
        const std::size_t after = tok.size() - i - 1;
        if (v > static_cast<double>(after))
            fail(std::string(tok[0]) + " " + what + " " + std::string(tok[i]) +
                 " is more than the " + plural(after, "field") + " after it");
        if (v > kMaxCount)
            fail(std::string(tok[0]) + " " + what + " " + std::string(tok[i]) + " is more than " +
                 std::to_string(static_cast<long>(kMaxCount)));
        return static_cast<std::size_t>(v);
    }

    void expectFields(std::size_t expected, const std::string& what) const {
        if (tok.size() != expected)
            fail(std::string(tok[0]) + " " + what + " has " + plural(tok.size(), "field") +
                 ", expected " + std::to_string(expected));
    }

    // A laser's mount (its pose on the robot) must be finite: every point depends on it.
    void checkMount(const mrpt::poses::CPose3D& mount, const std::string& from) const {
        if (!finitePose(mount.x(), mount.y(), mount.yaw()))
            fail(std::string(tok[0]) + " " + from + " is not finite: the laser mount is unknown");
    }

    void param() {
        if (tok.size() < 3) fail("PARAM needs a name and a value");
        const std::string name(tok[1]);
        auto value = [&] {  // the PARAMs kfd uses: finite numbers
            const double v = number(2);
            if (!std::isfinite(v))
                fail("PARAM " + name + " ('" + std::string(tok[2]) + "') is not finite");
            return v;
        };
        if (name == "robot_front_laser_max")
            front.max_range = value();
        else if (name == "robot_rear_laser_max")
            rear.max_range = value();
        else if (name == "laser_front_laser_resolution")
            front.resolution_deg = value();
        else if (name == "laser_rear_laser_resolution")
            rear.resolution_deg = value();
        else if (name == "robot_frontlaser_offset")
            front.offset_x = value(), front.offset_given = true;
        else if (name == "robot_frontlaser_side_offset")
            front.offset_side = value(), front.offset_given = true;
        else if (name == "robot_frontlaser_angular_offset")
            front.offset_angle = value(), front.offset_given = true;
        else if (name == "robot_rearlaser_offset")
            rear.offset_x = value(), rear.offset_given = true;
        else if (name == "robot_rearlaser_side_offset")
            rear.offset_side = value(), rear.offset_given = true;
        else if (name == "robot_rearlaser_angular_offset")
            rear.offset_angle = value(), rear.offset_given = true;
    }

    void pushOdometry(double x, double y, double theta, double stamp) {
        auto odo = std::make_shared<CObservationOdometry>();
        odo->sensorLabel = "ODOMETRY";
        odo->timestamp = mrpt::Clock::fromDouble(stamp);
        odo->odometry = CPose2D(x, y, theta);
        tracker.onObservation(*odo);
        SourceEntry e;
        e.kind = SourceEntry::Kind::Observation;
        e.observation = std::move(odo);
        e.odometry = tracker.current();
        ready.push_back(std::move(e));
    }

    // A scan of `n` beams from tok[first], valid when 0 < r < max_range.
    CObservation2DRangeScan::Ptr scanOf(std::size_t first, std::size_t n, double max_range,
                                        double stamp) const {
        auto s = std::make_shared<CObservation2DRangeScan>();
        s->sensorLabel = std::string(tok[0]);
        s->timestamp = mrpt::Clock::fromDouble(stamp);
        s->rightToLeft = true;
        s->maxRange = static_cast<float>(max_range);
        s->resizeScan(n);
        for (std::size_t i = 0; i < n; ++i) {
            const double r = number(first + i);
            const float rf = std::isfinite(r) ? static_cast<float>(r) : 0.0f;
            s->setScanRange(i, rf);
            s->setScanRangeValidity(i, std::isfinite(r) && r > 0.0 && r < max_range);
        }
        return s;
    }

    void pushScan(CObservation2DRangeScan::Ptr s) {
        SourceEntry e;
        e.kind = SourceEntry::Kind::Observation;
        e.observation = std::move(s);
        e.odometry = tracker.current();
        ready.push_back(std::move(e));
    }

    void flaser(const LaserParams& p) {
        if (tok.size() < 2) fail(std::string(tok[0]) + " without a reading count");
        const std::size_t n = count(1, "reading count");
        expectFields(n + 11, "with " + plural(n, "reading"));
        const std::size_t k = 2 + n;
        const double lx = number(k), ly = number(k + 1), lth = number(k + 2);
        const double ox = number(k + 3), oy = number(k + 4), oth = number(k + 5);
        const double stamp = number(k + 6);
        auto s = scanOf(2, n, p.max_range, stamp);
        const double res = p.resolution_deg > 0.0 ? p.resolution_deg : defaultResolution(n);
        s->aperture = static_cast<float>(res * static_cast<double>(n) * kDeg);
        if (p.offset_given)
            s->sensorPose =
                mrpt::poses::CPose3D(p.offset_x, p.offset_side, 0.0, p.offset_angle, 0.0, 0.0);
        else
            s->sensorPose = mrpt::poses::CPose3D(CPose2D(lx, ly, lth) - CPose2D(ox, oy, oth));
        checkMount(s->sensorPose, "laser pose (x y theta) or odometry (odom_x odom_y odom_theta)");
        pushOdometry(ox, oy, oth, stamp);
        pushScan(std::move(s));
    }

    // RAWLASERk (robot = false) and ROBOTLASERk (robot = true).
    void rawlaser(bool robot) {
        if (tok.size() < 9) fail(std::string(tok[0]) + " is cut short");
        const double start = number(2), fov = number(3), max_range = number(5);
        const std::size_t n = count(8, "reading count");
        if (tok.size() < 10 + n) fail(std::string(tok[0]) + " is cut short");
        const std::size_t nrem = count(9 + n, "remission count");
        const std::size_t tail = robot ? 14 : 3;
        expectFields(10 + n + nrem + tail,
                     "with " + plural(n, "reading") + " and " + plural(nrem, "remission"));
        const std::size_t k = 10 + n + nrem;
        const double stamp = number(tok.size() - 3);
        auto s = scanOf(9, n, max_range, stamp);
        s->aperture = static_cast<float>(fov);
        CPose2D mount(0.0, 0.0, 0.0);
        if (robot) {
            const CPose2D laser(number(k), number(k + 1), number(k + 2));
            const CPose2D base(number(k + 3), number(k + 4), number(k + 5));
            mount = laser - base;
            pushOdometry(base.x(), base.y(), base.phi(), stamp);
        }
        s->sensorPose = mrpt::poses::CPose3D(mount + CPose2D(0.0, 0.0, start + 0.5 * fov));
        checkMount(s->sensorPose, robot ? "start angle, field of view, laser pose or robot pose"
                                        : "start angle or field of view");
        pushScan(std::move(s));
    }

    // Parses lines until one yields entries; false at the end of the file.
    bool readMore() {
        while (ready.empty()) {
            if (!lines.next(line)) return false;
            if (!tokenize(line, tok))
                fail("more than " + std::to_string(kMaxFields) + " fields (not a CARMEN log?)");
            if (unparsable(line, tok)) {  // skipped, counted
                if (counts.lines_unparsable++ == 0) counts.first_unparsable_line = lines.number();
                counts.bytes_unparsable += lines.bytes();
                continue;
            }
            bytes_parsed += lines.bytes();
            if (tok.empty() || tok[0].front() == '#') continue;
            const std::string_view kw = tok[0];
            if (kw == "PARAM") {
                param();
            } else if (kw == "FLASER") {
                flaser(front);
            } else if (kw == "RLASER") {
                flaser(rear);
            } else if (kw.size() == 9 && kw.substr(0, 8) == "RAWLASER" && kw[8] >= '1' &&
                       kw[8] <= '4') {
                rawlaser(false);
            } else if (kw.size() == 11 && kw.substr(0, 10) == "ROBOTLASER" && kw[10] >= '1' &&
                       kw[10] <= '2') {
                rawlaser(true);
            } else if (kw == "ODOM") {
                expectFields(10, "line");
                pushOdometry(number(1), number(2), number(3), number(7));
            }  // other keywords: skipped
        }
        return true;
    }
};

CarmenSource::CarmenSource(const std::string& path) : impl_(std::make_unique<Impl>(path)) {}
CarmenSource::~CarmenSource() = default;

bool CarmenSource::next(SourceEntry& e) {
    Impl& d = *impl_;
    if (d.ready.empty() && !d.readMore()) {
        const SourceCounters& c = d.counts;
        if (c.bytes_unparsable > d.bytes_parsed)
            throw CarmenError(d.path +
                                  ": most of the log is not CARMEN text (binary data or another "
                                  "format?): " +
                                  std::to_string(c.bytes_unparsable) + " of its " +
                                  std::to_string(c.bytes_unparsable + d.bytes_parsed) +
                                  " bytes, in " + plural(c.lines_unparsable, "line") +
                                  ", the first at line " + std::to_string(c.first_unparsable_line),
                              d.path);
        if (d.entries == 0)
            throw CarmenError(d.path + ": no laser or odometry lines (not a CARMEN log?)", d.path);
        return false;
    }
    e = std::move(d.ready.front());
    d.ready.pop_front();
    e.index = d.entries++;
    e.objects_read = d.lines.number();
    return true;
}

const std::string& CarmenSource::path() const { return impl_->path; }
std::uint64_t CarmenSource::bytesRead() const { return impl_->lines.position(); }
std::uint64_t CarmenSource::bytesTotal() const { return impl_->lines.total(); }
std::size_t CarmenSource::line() const { return impl_->lines.number(); }
SourceCounters CarmenSource::counters() const { return impl_->counts; }

SourceListing listCarmen(const std::string& path) {
    LineReader lines(path);
    SourceListing l;
    l.path = path;
    l.format = LogFormat::Carmen;
    std::map<std::string, SourceListing::Stream> kinds;
    std::vector<std::string> order;
    std::string line;
    std::vector<std::string_view> tok;
    std::size_t comments = 0, unparsed = 0;
    while (lines.next(line)) {
        if (!tokenize(line, tok))
            throw CarmenError(path + ":" + std::to_string(lines.number()) + ": more than " +
                                  std::to_string(kMaxFields) + " fields (not a CARMEN log?)",
                              path);
        if (unparsable(line, tok)) {
            ++unparsed;
            continue;
        }
        if (tok.empty() || tok[0].front() == '#') {
            comments += tok.empty() ? 0 : 1;
            continue;
        }
        const std::string kw(tok[0]);
        if (kw == "PARAM") {
            if (tok.size() >= 3)
                l.choices.push_back("PARAM " + std::string(tok[1]) + " = " + std::string(tok[2]));
            continue;
        }
        auto [it, fresh] = kinds.try_emplace(kw);
        SourceListing::Stream& s = it->second;
        if (fresh) {
            order.push_back(kw);
            s.name = kw;
            const bool laser = kw == "FLASER" || kw == "RLASER" || kw.rfind("RAWLASER", 0) == 0 ||
                               kw.rfind("ROBOTLASER", 0) == 0;
            s.type = laser ? (kw.rfind("RAWLASER", 0) == 0 ? "2D scan" : "2D scan + odometry")
                     : kw == "ODOM" ? "odometry"
                                    : "skipped";
        }
        ++s.count;
        double t = 0.0;
        if (tok.size() >= 4) {
            const std::string_view f = tok[tok.size() - 3];
            if (std::from_chars(f.data(), f.data() + f.size(), t).ec == std::errc()) {
                if (s.count == 1) s.first_stamp = t;
                s.last_stamp = t;
            }
        }
    }
    for (const auto& k : order) l.streams.push_back(kinds[k]);
    l.detail = "CARMEN log, " + plural(lines.number(), "line") + " (" +
               plural(comments, "comment") +
               (unparsed ? ", " + std::to_string(unparsed) + " not CARMEN text" : "") + ")";
    return l;
}

}  // namespace kfd
