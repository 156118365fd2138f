#include "kfd/mrpt/stream_filter.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <utility>

#include "kfd/algorithms/keyframe_guards.h"
#include "kfd/algorithms/keyframe_selector.h"
#include "kfd/io/source.h"
#include "kfd/mrpt/default_stages.h"
#include "kfd/mrpt/scan_check.h"
#include "kfd/pipeline/format.h"
#include "kfd/stages/denoise_result.h"

namespace kfd {
namespace {

// "skipped:<why>" as static text (ScanRecord::reason).
const char* skippedReason(ScanSkipReason r) {
    switch (r) {
        case ScanSkipReason::NoBeams:
            return "skipped:no_beams";
        case ScanSkipReason::TooManyBeams:
            return "skipped:too_many_beams";
        case ScanSkipReason::BadAperture:
            return "skipped:bad_aperture";
        case ScanSkipReason::None:
            break;
    }
    return "ok";
}

// Marks invalid in `obs` the first n beams whose flag in `valid` is 0 (the stages' removals;
// no beam made valid again). memchr skips the runs of valid beams: most beams of most scans.
void writeBack(const std::uint8_t* valid, std::size_t n, mrpt::obs::CObservation2DRangeScan& obs) {
    const std::uint8_t* end = valid + n;
    for (const void* hit = std::memchr(valid, 0, n); hit;) {
        const auto* p = static_cast<const std::uint8_t*>(hit);
        const auto i = static_cast<std::size_t>(p - valid);
        if (obs.getScanRangeValidity(i)) obs.setScanRangeValidity(i, false);
        ++p;
        hit = p < end ? std::memchr(p, 0, static_cast<std::size_t>(end - p)) : nullptr;
    }
}

// Writes a scan the stages resampled (beam_count: a beam count other than the observation's)
// into `obs`: its beams, aperture, direction and intensities replaced by the scan's.
void writeResampled(const Scan& scan, mrpt::obs::CObservation2DRangeScan& obs) {
    const std::size_t n = scan.size();
    obs.resizeScan(n);
    obs.aperture = static_cast<float>(scan.geometry.aperture);
    obs.rightToLeft = scan.geometry.right_to_left;
    for (std::size_t i = 0; i < n; ++i) {
        obs.setScanRange(i, scan.range[i]);
        obs.setScanRangeValidity(i, scan.valid[i] != 0);
    }
    const bool has_intensity = scan.intensity.size() == n && n > 0;
    obs.setScanHasIntensity(has_intensity);
    if (has_intensity)
        for (std::size_t i = 0; i < n; ++i)
            obs.setScanIntensity(i, static_cast<int32_t>(std::lround(scan.intensity[i])));
}

// The stages' result written into `obs`: the removed beams marked invalid or, when a stage
// resampled the scan, the whole scan replaced.
void writeScan(const Scan& scan, mrpt::obs::CObservation2DRangeScan& obs) {
    if (scan.size() == obs.getScanSize())
        writeBack(scan.valid.data(), scan.size(), obs);
    else
        writeResampled(scan, obs);
}

}  // namespace

StreamFilter::StreamFilter(const Pipeline::Params& params, StageFactory extra,
                           bool one_scan_latency)
    : params_(params), extra_(std::move(extra)) {
    // Validated now, not at the first scan; the first sensor takes this pipeline.
    spare_ = std::make_unique<Pipeline>(params_, defaultStageRegistry());
    outputs_ = StageOutputs(params_.stages, defaultStageRegistry());
    counters_.stage_totals = outputs_.zeroTotals();
    if (!one_scan_latency)
        for (const auto& stage : spare_->stages())
            if (stage->defers())
                throw ParameterError(
                    "next_scan",
                    std::string("next_scan = true: the ") + stage->name() +
                        " stage holds each keyframe until the next scan (one scan of latency), "
                        "which this caller does not handle (it constructs the door without "
                        "one_scan_latency, which kfd's tools all give); set next_scan = false");
}

StreamFilter::Sensor& StreamFilter::sensorFor(const std::string& label) {
    auto it = sensors_.find(label);
    if (it != sensors_.end()) {
        it->second.last_used = counters_.scans_in;
        return it->second;
    }
    while (sensors_.size() >= max_sensors_) evictOldest();
    Sensor s;
    s.last_used = counters_.scans_in;
    s.pipeline =
        spare_ ? std::move(spare_) : std::make_unique<Pipeline>(params_, defaultStageRegistry());
    if (extra_) extra_(*s.pipeline);
    return sensors_.emplace(label, std::move(s)).first->second;
}

StreamResult StreamFilter::process(mrpt::obs::CObservation2DRangeScan& obs,
                                   const std::optional<Pose2D>& odometry) {
    StreamResult res;
    res.scan = &obs;
    ScanRecord& rec = res.record;
    rec.index = counters_.scans_in++;
    rec.sensor = obs.sensorLabel;
    if (!laser_only_) rec.odometry = odometry;
    // The check converts into a spare buffer; the scan's sensor (and its pipeline) is looked up
    // only once the scan is known to be usable, and takes the buffer by a swap (no copy).
    const ScanCheck check = checkScan(obs, &rec.odometry, spare_scan_);
    res.bad_ranges = check.bad_ranges;
    res.bad_odometry = check.bad_odometry;
    counters_.beams_bad_range += check.bad_ranges;
    counters_.odometry_bad += check.bad_odometry ? 1 : 0;
    if (!check.ok()) {  // skipped: no stage runs
        res.skipped = rec.skipped = check.reject;
        rec.stamp = stampOf(obs);
        rec.reason = skippedReason(check.reject);
        rec.points_in = obs.getScanSize();
        ++counters_.scans_skipped;
        ++counters_.skipped_by_reason[static_cast<std::size_t>(check.reject)];
        return res;
    }

    Sensor& s = sensorFor(obs.sensorLabel);
    std::swap(s.scan, spare_scan_);
    // The geometry the stages see (after a beam_count stage's resampling): a driver whose
    // count varies restarts nothing when the chain fixes the count.
    const ScanGeometry g = s.pipeline->outputGeometry(s.scan.geometry);
    if (s.geometry.beams != 0 && g != s.geometry) {
        s.pipeline->reset();  // finishes a pending scan without its next
        collectFinished(s);
        res.geometry_reset = true;
    }
    s.geometry = g;
    s.scan.odometry = rec.odometry;
    rec.stamp = s.scan.timestamp;  // kfd::stampOf, taken by the check's conversion
    if (std::isfinite(s.scan.timestamp)) {
        res.stamp_backwards = std::isfinite(s.last_stamp) && s.scan.timestamp < s.last_stamp;
        s.last_stamp = s.scan.timestamp;
    }
    res.report = s.pipeline->process(s.scan);
    collectFinished(s);  // the sensor's scan before, when this one finished it
    res.keep = rec.kept = res.report.keep;
    // Written back: the beams the stages removed become invalid in the MRPT scan (ranges, beam
    // count and angles kept; no beam made valid again; only those beams are touched), or the
    // resampled scan replaces it (beam_count).
    writeScan(s.scan, obs);
    if (res.report.pending) {  // recorded once finished
        res.pending = true;
        s.held = res;
        return res;
    }
    record(res);
    return res;
}

void StreamFilter::evictOldest() {
    auto oldest = sensors_.begin();
    for (auto it = sensors_.begin(); it != sensors_.end(); ++it)
        if (it->second.last_used < oldest->second.last_used) oldest = it;
    if (oldest == sensors_.end()) return;
    Sensor& s = oldest->second;
    if (s.pipeline->finish()) collectFinished(s);  // its held keyframe is not lost
    sensors_.erase(oldest);
    ++counters_.sensors_evicted;
    drain();
}

void StreamFilter::collectFinished(Sensor& s) {
    if (!s.held.scan) return;  // nothing pending (always so without next_scan)
    ScanReport report;
    const Scan* done = s.pipeline->finished(report);
    if (!done) return;
    StreamResult res = std::move(s.held);
    s.held = StreamResult{};
    res.pending = false;
    res.report = report;
    res.keep = res.record.kept = report.keep;
    mrpt::obs::CObservation2DRangeScan& obs = *res.scan;
    writeScan(*done, obs);
    record(res);
    for (InOrder& w : in_order_)  // a process(.., done) call waits for it
        if (w.held && w.scan == res.scan) {
            w.result = std::move(res);
            w.held = false;
            return;
        }
    finished_.push_back(std::move(res));
}

StreamResult StreamFilter::process(mrpt::obs::CObservation2DRangeScan& scan,
                                   const std::optional<Pose2D>& odometry, OnFinished done) {
    StreamResult r = process(scan, odometry);
    InOrder w;
    w.scan = &scan;
    w.held = r.pending;
    w.result = r;
    w.done = std::move(done);
    in_order_.push_back(std::move(w));
    drain();
    return r;
}

void StreamFilter::then(std::function<void()> fn) {
    InOrder w;
    w.fn = std::move(fn);
    in_order_.push_back(std::move(w));
    drain();
}

void StreamFilter::drain() {
    while (!in_order_.empty() && !in_order_.front().held) {
        InOrder w = std::move(in_order_.front());
        in_order_.pop_front();
        if (w.fn) w.fn();
        if (w.done) w.done(w.result);
    }
}

bool StreamFilter::takeFinished(StreamResult& out) {
    if (finished_.empty()) return false;
    out = std::move(finished_.front());
    finished_.pop_front();
    return true;
}

void StreamFilter::finish() {
    const std::size_t before = finished_.size();
    for (auto& [label, s] : sensors_)
        if (s.pipeline->finish()) collectFinished(s);
    // In input order (several sensors): by the scans' indices.
    std::sort(finished_.begin() + static_cast<std::ptrdiff_t>(before), finished_.end(),
              [](const StreamResult& a, const StreamResult& b) {
                  return a.record.index < b.record.index;
              });
    drain();
}

std::size_t StreamFilter::pendingCount() const {
    std::size_t n = 0;
    for (const auto& [label, s] : sensors_) n += s.pipeline->holding() ? 1 : 0;
    return n;
}

// The record and the counters of a scan that ran through the pipeline.
void StreamFilter::record(StreamResult& res) {
    const ScanReport& rep = res.report;
    ScanRecord& rec = res.record;
    if (const auto* kf = rep.find<KeyframeDecision>()) {
        rec.reason = toString(kf->reason);
    } else {  // no keyframe stage: "kept", or the stage that dropped the scan
        rec.reason = "kept";
        for (const StageReport& sr : rep)
            if (sr.dropped) rec.reason = sr.name;
    }
    rec.points_in = rep.points_in;
    rec.removed_noise = rep.noiseRemoved();
    rec.surface_m = rep.surfaceRemoved();
    rec.points_out = rep.points_out;
    rec.microseconds = rep.microseconds;
    rec.report = rep;
    count(res);
}

namespace {

void countReason(ScanCounters& c, const char* reason) {
    for (auto& [name, n] : c.reasons)
        if (name == reason) {
            ++n;
            return;
        }
    c.reasons.emplace_back(reason, 1);
}

// Keeps in `v` the ScanCounters::kMostRemoved entries of largest key(r), largest first (ties:
// the one given first): the most-cut scans, the longest surface-like runs.
template <class T, class Key>
void keepLargest(std::vector<T>& v, const T& r, Key key) {
    const auto at = std::find_if(v.begin(), v.end(), [&](const T& o) { return key(r) > key(o); });
    if (at == v.end() && v.size() >= ScanCounters::kMostRemoved) return;
    v.insert(at, r);
    if (v.size() > ScanCounters::kMostRemoved) v.pop_back();
}

}  // namespace

// The counters of a recorded scan: the door's own, then the listed stages' declared ones.
void StreamFilter::count(const StreamResult& res) {
    const ScanReport& rep = res.report;
    const ScanRecord& rec = res.record;
    ScanCounters& c = counters_;
    c.stamps_backwards += res.stamp_backwards ? 1 : 0;
    c.geometry_resets += res.geometry_reset ? 1 : 0;
    c.points_in += rep.points_in;
    c.filter_seconds += rep.microseconds * 1e-6;
    outputs_.count(rep, c.stage_totals);
    countReason(c, rec.reason);
    if (!res.keep) {
        ++c.scans_dropped;
        return;
    }
    ++c.scans_kept;
    c.points_removed_noise += rec.removed_noise;
    // The share of the returns the denoisers saw (what the other stages left valid).
    const std::size_t usable = rep.points_out + rec.removed_noise;
    if (usable > 0)
        c.max_removed_noise_share =
            std::max(c.max_removed_noise_share,
                     static_cast<double>(rec.removed_noise) / static_cast<double>(usable));
    c.points_removed += rep.points_in - rep.points_out;
    if (rec.removed_noise > 0)
        keepLargest(c.most_removed, {rec.index, rec.stamp, rec.removed_noise, usable},
                    [](const ScanCounters::Removal& r) { return r.share(); });
    if (rec.surface_m > 0.0) {
        ++c.scans_surface_removed;
        keepLargest(c.surface_removed, {rec.index, rec.stamp, rec.surface_m},
                    [](const ScanCounters::SurfaceRemoval& r) { return r.length_m; });
    }
}

std::vector<std::string> reasonLines(const ScanCounters& c) {
    auto reasons = c.reasons;
    std::stable_sort(reasons.begin(), reasons.end(),
                     [](const auto& a, const auto& b) { return a.second > b.second; });
    std::vector<std::string> lines;
    for (const auto& [name, n] : reasons) {
        const char* meaning = describeKeyframeReason(name);
        const std::string why = meaning          ? meaning
                                : name == "kept" ? "kept: no stage of the pipeline drops scans"
                                : name.rfind("skipped:", 0) == 0
                                    ? "skipped: a geometry kfd cannot use (see 'skipped')"
                                    : "dropped by the " + name + " stage";
        lines.push_back(format("%s %-14s %6zu  %s", lines.empty() ? "reasons " : "        ",
                               name.c_str(), n, why.c_str()));
    }
    if (!c.most_removed.empty()) {
        std::string m = "most removed (kfd-render --index N draws one):";
        for (const auto& r : c.most_removed)
            m += format(" scan %zu %.1f %% (%zu of %zu);", r.index, 100.0 * r.share(), r.removed,
                        r.usable);
        lines.push_back(m);
    }
    if (c.scans_surface_removed > 0) {
        std::string m = format(
            "looks like a surface: on %zu kept scans the denoiser removed a straight run of "
            ">= 0.5 m (a wall taken for noise?):",
            c.scans_surface_removed);
        for (const auto& r : c.surface_removed)
            m += format(" scan %zu %.2f m;", r.index, r.length_m);
        lines.push_back(m);
    }
    return lines;
}

std::string noUsableScan(const ScanCounters& c, const SourceCounters& source,
                         const std::string& log) {
    if (c.scans_in == 0) return "no laser scan in " + log;
    if (c.scans_skipped < c.scans_in) return {};
    std::string why;
    for (std::size_t r = 1; r < kScanSkipReasons; ++r)
        if (c.skipped_by_reason[r])
            why += (why.empty() ? "" : "; ") +
                   std::string(toString(static_cast<ScanSkipReason>(r))) + " " +
                   std::to_string(c.skipped_by_reason[r]) + ": " +
                   describe(static_cast<ScanSkipReason>(r));
    if (source.scans_bad_angles)
        why += "; of them " + plural(source.scans_bad_angles, "LaserScan") +
               " whose angle fields do not match their beam count";
    return "no usable scan in " + log + ": " + (c.scans_in == 1 ? "its " : "all ") +
           plural(c.scans_in, "scan") + " skipped (" + why + ")";
}

const Clusters* StreamFilter::lastClusters(const std::string& sensor_label) const {
    const auto it = sensors_.find(sensor_label);
    return it == sensors_.end() ? nullptr : it->second.pipeline->lastClusters();
}

}  // namespace kfd
