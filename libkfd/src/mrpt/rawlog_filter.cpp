#include "kfd/mrpt/rawlog_filter.h"

#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/poses/CPose2D.h>
#include <mrpt/serialization/CArchive.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>

#include "kfd/core/cancel.h"
#include "kfd/core/output_paths.h"

#include "kfd/core/denoiser.h"
#include "kfd/mrpt/open_source.h"
#include "kfd/mrpt/scan_adapter.h"
#include "kfd/mrpt/scan_check.h"

namespace kfd {
namespace {

namespace fs = std::filesystem;
using mrpt::obs::CActionCollection;
using mrpt::obs::CActionRobotMovement2D;
using mrpt::obs::CObservation2DRangeScan;
using mrpt::obs::CSensoryFrame;
using mrpt::poses::CPose2D;

// Runs fn; the errors of the sources and of the bag writer (SourceError, BagError,
// CarmenError) come out as RawlogError, the class RawlogFilter reports (a RawlogError as it
// is). `field`: the path the error is about, when it is not the error's own (the output).
template <class Fn>
decltype(auto) asRawlogError(Fn&& fn, const std::string& field = {}) {
    try {
        return fn();
    } catch (const RawlogError&) {
        throw;
    } catch (const SourceError& e) {
        throw RawlogError(e.what(), field.empty() ? e.field() : field);
    }
}

class CsvWriter {
  public:
    void open(const fs::path& path, const std::string& final_path) {
        out_.open(path);
        if (!out_) throw RawlogError("cannot write the stats file " + final_path, final_path);
        out_ << "index,timestamp,sensor,keyframe,reason,p_common,p_threshold,references,"
                "points_in,removed_range,clusters,noise_clusters,removed_noise,points_out,"
                "microseconds,view_change,changed_fraction,degeneracy,corridor\n";
    }
    bool isOpen() const { return out_.is_open(); }
    void row(std::size_t index, double stamp, const StreamResult& r) {
        const ScanReport& s = r.report;
        const auto* kf = s.find<KeyframeDecision>();
        const auto k = s.findOrDefault<KeyframeDecision>();
        const auto d = s.findOrDefault<DistanceFilter::Result>();
        const auto n = s.findOrDefault<Denoiser::Result>();
        char buf[512];
        std::snprintf(
            buf, sizeof(buf),
            "%zu,%.6f,%s,%d,%s,%.6f,%.6f,%zu,%zu,%zu,%zu,%zu,%zu,%zu,%.2f,%.4f,%.4f,%.4f,%d\n",
            index, stamp, r.sensor_label.c_str(), r.keep ? 1 : 0,
            kf ? toString(kf->reason) : "none", k.p_common, k.p_threshold, k.references,
            s.points_in, d.removed_non_finite + d.removed_out_of_range, n.clusters,
            n.noise_clusters, s.noiseRemoved(), s.points_out, s.microseconds, k.view_change,
            k.changed_fraction, k.degeneracy, k.corridor ? 1 : 0);
        out_ << buf;
    }
    void skippedRow(std::size_t index, double stamp, const std::string& sensor, ScanSkipReason why,
                    std::size_t points_in) {
        char buf[256];
        std::snprintf(buf, sizeof(buf), "%zu,%.6f,%s,0,skipped:%s,0,0,0,%zu,0,0,0,0,0,0,0,0,1,0\n",
                      index, stamp, sensor.c_str(), toString(why), points_in);
        out_ << buf;
    }
    void close() {
        if (!out_.is_open()) return;
        out_.close();
        if (out_.fail()) throw RawlogError("failed writing the stats file");
    }

  private:
    std::ofstream out_;
};

class Run {
  public:
    Run(const RawlogFilterOptions& o, RawlogFilterSummary& s)
        : opts_(o), sum_(s), filter_(o.pipeline) {}

    void execute();

  private:
    void handleActions(const std::shared_ptr<CActionCollection>& acts);
    void handleFrame(const std::shared_ptr<CSensoryFrame>& sf);
    // Processes one scan; returns true when kept.
    bool handleScan(CObservation2DRangeScan& scan);
    void noteSensor(const CObservation2DRangeScan& scan, const std::optional<Pose2D>& odometry,
                    const StreamResult& r);
    void write(const mrpt::serialization::CSerializable& obj);
    void flushPendingAction(bool frame_kept);

    const RawlogFilterOptions& opts_;
    RawlogFilterSummary& sum_;
    StreamFilter filter_;
    CsvWriter csv_;
    mrpt::io::CFileGZOutputStream out_;
    std::optional<mrpt::serialization::CArchiveStreamBase<mrpt::io::CFileGZOutputStream>> arch_;
    std::optional<BagWriter> bag_;                // a bag output (instead of out_/arch_)
    std::shared_ptr<CActionCollection> pending_;  // action waiting for its sensory frame
    CPose2D carry_;                               // odometry of dropped frames, not yet written
    bool have_carry_ = false;
    std::optional<Pose2D> odometry_;  // absolute odometry, for the motion guards
    bool saw_frames_ = false, saw_observations_ = false;
    std::size_t scan_index_ = 0;
    // The first sensor's stamps counted for its rate (SensorSummary::rate_hz).
    std::size_t rate_stamps_ = 0;
    double first_rate_stamp_ = 0.0;
};

void Run::write(const mrpt::serialization::CSerializable& obj) {
    try {
        (*arch_) << obj;
    } catch (const std::exception& e) {
        throw RawlogError(std::string("failed writing the output: ") + e.what());
    }
    ++sum_.objects_out;
}

void Run::noteSensor(const CObservation2DRangeScan& scan, const std::optional<Pose2D>& odometry,
                     const StreamResult& r) {
    SensorSummary& s = sum_.sensor;
    if (s.beams == 0) {
        const ScanGeometry g = geometryOf(scan);
        s.label = scan.sensorLabel;
        s.beams = g.beams;
        s.aperture_deg = g.aperture * 180.0 / kPi;
        s.resolution_deg = g.resolution() * 180.0 / kPi;
    }
    if (scan.sensorLabel != s.label) return;
    s.odometry = s.odometry || odometry.has_value();
    const double t = stampOf(scan);
    if (std::isfinite(t) && rate_stamps_ < SensorSummary::kMaxRateScans) {
        if (rate_stamps_ == 0) first_rate_stamp_ = t;
        ++rate_stamps_;
        if (rate_stamps_ > 1 && t > first_rate_stamp_)
            s.rate_hz = static_cast<double>(rate_stamps_ - 1) / (t - first_rate_stamp_);
    }
    if (r.keep)
        if (const auto* d = r.report.find<Denoiser::Result>())
            if (d->variant == DenoiseVariant::Evidence) s.range_noise_m = d->sigma;
}

bool Run::handleScan(CObservation2DRangeScan& scan) {
    ++sum_.scans_in;
    const double stamp = stampForOutput(stampOf(scan));
    // A scan with a bad geometry is skipped (dropped from the output, counted); bad ranges and
    // odometry are repaired by checkScan and the scan goes on.
    std::optional<Pose2D> odometry = odometry_;
    const ScanCheck check = checkScan(scan, &odometry);
    sum_.beams_bad_range += check.bad_ranges;
    sum_.odometry_bad += check.bad_odometry ? 1 : 0;
    if (!check.ok()) {
        ++sum_.scans_skipped;
        ++sum_.skipped_by_reason[static_cast<std::size_t>(check.reject)];
        if (csv_.isOpen())
            csv_.skippedRow(scan_index_, stamp, scan.sensorLabel, check.reject, scan.getScanSize());
        ++scan_index_;
        return false;
    }
    StreamResult r;
    try {
        r = filter_.process(scan, odometry);
    } catch (const ScanError& e) {  // not reached: checkScan passed
        throw RawlogError("scan " + std::to_string(scan_index_) + ": " + e.what());
    }
    noteSensor(scan, odometry, r);
    sum_.stamps_backwards += r.stamp_backwards ? 1 : 0;
    sum_.points_in += r.report.points_in;
    sum_.filter_seconds += r.report.microseconds * 1e-6;
    sum_.geometry_resets += r.geometry_reset ? 1 : 0;
    if (const auto* kf = r.report.find<KeyframeDecision>()) {
        sum_.scans_corridor += kf->corridor ? 1 : 0;
        sum_.keyframes_corridor += kf->reason == KeyframeReason::Corridor ? 1 : 0;
    }
    if (r.keep) {
        ++sum_.scans_kept;
        const auto d = r.report.findOrDefault<DistanceFilter::Result>();
        sum_.points_removed_range += d.removed_non_finite + d.removed_out_of_range;
        sum_.points_removed_noise += r.report.noiseRemoved();
    } else {
        ++sum_.scans_dropped;
    }
    if (csv_.isOpen()) csv_.row(scan_index_, stamp, r);
    ++scan_index_;
    return r.keep;
}

void Run::handleActions(const std::shared_ptr<CActionCollection>& acts) {
    // Two actions in a row (no frame between): the first stands on its own.
    if (pending_) flushPendingAction(true);
    pending_ = acts;
}

// Writes the pending action (with any carried odometry composed in) or, when its frame was
// dropped, folds its motion into the carry for the next kept action.
void Run::flushPendingAction(bool frame_kept) {
    if (!pending_) return;
    auto acts = pending_;
    pending_.reset();
    auto mv = acts->getBestMovementEstimation();
    if (!frame_kept) {
        if (mv) {
            carry_ = have_carry_ ? carry_ + mv->rawOdometryIncrementReading
                                 : mv->rawOdometryIncrementReading;
            have_carry_ = true;
        }
        ++sum_.actions_merged;
        return;
    }
    if (have_carry_) {
        if (mv) {
            auto copy = std::make_shared<CActionRobotMovement2D>(*mv);
            copy->computeFromOdometry(carry_ + mv->rawOdometryIncrementReading,
                                      mv->motionModelConfiguration);
            // Replace the movement in a copy of the collection, keeping other actions.
            auto merged = std::make_shared<CActionCollection>();
            for (std::size_t i = 0; i < acts->size(); ++i) {
                auto a = acts->get(i);
                if (a.get() == mv.get())
                    merged->insert(*copy);
                else
                    merged->insert(*a);
            }
            acts = merged;
        } else {
            CActionRobotMovement2D m;
            m.computeFromOdometry(carry_, CActionRobotMovement2D::TMotionModelOptions());
            auto merged = std::make_shared<CActionCollection>(*acts);
            merged->insert(m);
            acts = merged;
        }
        have_carry_ = false;
        carry_ = CPose2D();
    }
    write(*acts);
}

void Run::handleFrame(const std::shared_ptr<CSensoryFrame>& sf) {
    std::size_t scans = 0;
    for (auto it = sf->begin(); it != sf->end();) {
        auto scan = std::dynamic_pointer_cast<CObservation2DRangeScan>(*it);
        if (!scan) {
            ++it;
            continue;
        }
        ++scans;
        if (handleScan(*scan)) {
            ++it;
        } else {
            it = sf->erase(it);
        }
    }
    const bool frame_kept = !(scans > 0 && sf->size() == 0);
    flushPendingAction(frame_kept);
    if (frame_kept)
        write(*sf);
    else
        ++sum_.objects_dropped;
}

void Run::execute() {
    const auto t0 = std::chrono::steady_clock::now();
    std::error_code ec;
    if (!fs::is_regular_file(opts_.input, ec))
        throw RawlogError("input log not found: " + opts_.input);
    if (opts_.output.empty()) throw RawlogError("no output file given");
    // Before anything is opened for writing: no output may be an input or the other output.
    try {
        checkOutputPaths({{"input rawlog", opts_.input}},
                         {{"output rawlog", opts_.output}, {"stats file", opts_.stats_csv}});
    } catch (const PathError& e) {  // reported like every other output problem of this class
        throw RawlogError(e.what(), e.field());
    }

    const std::string& o = opts_.output;
    sum_.output_format = o.size() > 4 && o.compare(o.size() - 4, 4, ".bag") == 0
                             ? LogFormat::Bag
                             : LogFormat::Rawlog;
    sum_.input_format = asRawlogError([&] { return detectFormat(opts_.input); });
    if (sum_.output_format == LogFormat::Bag && sum_.input_format != LogFormat::Bag)
        throw RawlogError("a bag output (" + o + ") needs a ROS bag input; " + opts_.input +
                              " is read as: " + toString(sum_.input_format) +
                              " (write a .rawlog instead)",
                          o);
    const auto source =
        asRawlogError([&] { return openSource(opts_.input, sum_.input_format, opts_.source); });
    const std::uint64_t total = source->bytesTotal();
    if (const auto* bag = dynamic_cast<const BagSource*>(source.get())) {
        const BagChoice& c = bag->choice();
        sum_.layout = "scans " + c.scan_topic + ", odometry " +
                      (c.odometry == BagChoice::Odometry::None ? std::string("none")
                       : c.odometry == BagChoice::Odometry::Tf
                           ? c.odom_topic + " " + c.odom_frame + "->" + c.base_frame
                           : c.odom_topic);
    }

    // Both outputs are written under temporary names beside them and renamed at the end; on
    // any failure or cancellation the destructors remove them.
    TempOutputFile tmp(opts_.output);
    std::optional<TempOutputFile> tmp_csv;
    if (sum_.output_format == LogFormat::Bag) {
        asRawlogError([&] { bag_.emplace(tmp.path().string(), opts_.bag); }, opts_.output);
    } else {
        if (!out_.open(tmp.path().string(), opts_.compress_level))
            throw RawlogError("cannot write the output next to " + opts_.output, opts_.output);
        arch_.emplace(out_);
    }
    if (!opts_.stats_csv.empty()) {
        tmp_csv.emplace(opts_.stats_csv);
        csv_.open(tmp_csv->path(), opts_.stats_csv);
    }

    RawlogProgress progress;
    progress.bytes_total = total;
    const std::size_t every = std::max<std::size_t>(1, opts_.progress_every);
    SourceEntry e;
    while (asRawlogError([&] { return source->next(e); })) {
        throwIfCancelled();
        const std::size_t before = sum_.objects_in;
        sum_.objects_in = e.objects_read;
        odometry_ = e.odometry;
        switch (e.kind) {
            case SourceEntry::Kind::Frame:
                saw_frames_ = true;
                if (e.action) handleActions(e.action);
                handleFrame(e.frame);
                break;
            case SourceEntry::Kind::Action:
                saw_frames_ = true;
                handleActions(e.action);
                break;
            case SourceEntry::Kind::Observation: {
                saw_observations_ = true;
                flushPendingAction(true);
                auto scan = std::dynamic_pointer_cast<CObservation2DRangeScan>(e.observation);
                if (!scan) {
                    if (!bag_)
                        write(*e.observation);  // a bag's own odometry messages are
                                                // Native entries, copied below
                } else if (!handleScan(*scan)) {
                    ++sum_.objects_dropped;
                } else if (!bag_) {
                    write(*scan);
                } else if (e.native) {
                    sum_.points_marked += asRawlogError(
                        [&] { return bag_->writeScan(*e.native, *scan); }, opts_.output);
                    ++sum_.objects_out;
                }
                break;
            }
            case SourceEntry::Kind::Other:
                flushPendingAction(true);
                write(*e.other);
                break;
            case SourceEntry::Kind::Native:  // another topic of a bag
                if (bag_) {
                    asRawlogError([&] { bag_->copy(*e.native); }, opts_.output);
                    ++sum_.objects_out;
                }
                break;
        }
        if (opts_.on_progress && before / every != sum_.objects_in / every) {
            progress.bytes_read = source->bytesRead();
            progress.objects = sum_.objects_in;
            progress.scans_in = sum_.scans_in;
            progress.scans_kept = sum_.scans_kept;
            opts_.on_progress(progress);
        }
    }
    if (sum_.objects_in == 0) throw RawlogError("no objects in " + opts_.input + ": not a rawlog?");
    flushPendingAction(true);
    if (have_carry_) {  // the last frames were dropped: keep their motion as a final action
        CActionCollection acts;
        CActionRobotMovement2D m;
        m.computeFromOdometry(carry_, CActionRobotMovement2D::TMotionModelOptions());
        acts.insert(m);
        write(acts);
        --sum_.actions_merged;  // that motion was written, not merged away
        have_carry_ = false;
    }
    arch_.reset();
    if (bag_) {
        asRawlogError([&] { bag_->close(); }, opts_.output);
    } else {
        out_.close();
    }
    csv_.close();
    throwIfCancelled();
    tmp.commit();
    if (tmp_csv) tmp_csv->commit();

    if (sum_.input_format == LogFormat::Carmen)
        sum_.layout = "FLASER/RLASER/RAWLASER/ROBOTLASER and ODOM lines";
    else if (sum_.input_format == LogFormat::Rawlog)
        sum_.layout = saw_frames_ && saw_observations_ ? "mixed"
                      : saw_frames_                    ? "actions+sensory-frames"
                                                       : "observations";
    sum_.sensors = filter_.sensorCount();
    sum_.wall_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (opts_.on_progress) {
        progress.bytes_read = total;
        progress.objects = sum_.objects_in;
        progress.scans_in = sum_.scans_in;
        progress.scans_kept = sum_.scans_kept;
        opts_.on_progress(progress);
    }
}

}  // namespace

RawlogFilterSummary RawlogFilter::run(const RawlogFilterOptions& opts) {
    RawlogFilterSummary sum;
    Run(opts, sum).execute();
    return sum;
}

}  // namespace kfd
