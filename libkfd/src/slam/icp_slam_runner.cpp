#include "kfd/slam/icp_slam_runner.h"

#include <mrpt/config/CConfigFile.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/poses/CPose3DPDF.h>
#include <mrpt/slam/CMetricMapBuilderICP.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <deque>
#include <filesystem>
#include <fstream>
#include <string_view>

#include "kfd/baselines/decimate_stage.h"
#include "kfd/baselines/motion_stage.h"
#include "kfd/eval/ate.h"
#include "kfd/io/open_source.h"
#include "kfd/io/scan_csv.h"
#include "kfd/io/source.h"
#include "kfd/mrpt/config.h"
#include "kfd/mrpt/scan_check.h"
#include "kfd/mrpt/stream_filter.h"
#include "kfd/os/cancel.h"
#include "kfd/pipeline/format.h"
#include "kfd/slam/gap_check.h"
#include "kfd/stages/keyframe_stage.h"

namespace kfd {
namespace {

namespace fs = std::filesystem;
using mrpt::obs::CObservation2DRangeScan;
constexpr const char* kSect = "MappingApplication";
// At most this many dropped scans wait for a re-match (since ICP's last accepted correction).
constexpr std::size_t kMaxHeld = 64;

// One step of MRPT's icp-slam: an observation on its own, or an odometry action with a sensory
// frame.
struct IcpSlamStep {
    mrpt::obs::CObservation::Ptr observation;
    mrpt::obs::CActionCollection::Ptr action;
    mrpt::obs::CSensoryFrame::Ptr frame;
};

// MRPT's icp-slam reads the log with CRawlog::getActionObservationPairOrObservation: an
// observation on its own is one step; an action is paired with the next sensory frame, and
// whatever lies between them (even another action or observation) is skipped, as is a frame
// without an action. This reproduces that grouping over a source's entries.
class IcpSlamSteps {
  public:
    /// True when `e` completes a step, written to `step`.
    bool feed(const SourceEntry& e, IcpSlamStep& step) {
        using Kind = SourceEntry::Kind;
        step = IcpSlamStep();
        if (pending_) {  // an action waiting for its frame
            if (e.kind != Kind::Frame) return false;
            step.action = std::move(pending_);
            step.frame = e.frame;
            return true;
        }
        if (e.kind == Kind::Observation) {
            step.observation = e.observation;
            return true;
        }
        if (e.kind == Kind::Frame && e.action) {
            step.action = e.action;
            step.frame = e.frame;
            return true;
        }
        if (e.kind == Kind::Action) pending_ = e.action;
        return false;
    }

  private:
    mrpt::obs::CActionCollection::Ptr pending_;
};

std::unique_ptr<Source> openLog(const std::string& path, const SourceOptions& options) {
    try {
        return openSource(path, options);
    } catch (const SourceError& e) {
        throw SlamError(e.what(), path);
    }
}

bool nextEntry(Source& source, SourceEntry& e) {
    try {
        return source.next(e);
    } catch (const SourceError& err) {
        throw SlamError(err.what(), source.path());
    }
}

// Runs fn, a call into MRPT; what MRPT throws becomes a SlamError that says what kfd was doing
// (doing(), called only then), then MRPT's message (kfd::plainMessage: no banner, no stack).
template <class Fn, class Doing>
void callMrpt(Fn&& fn, Doing&& doing, const std::string& field) {
    try {
        fn();
    } catch (const Error&) {
        throw;
    } catch (const std::bad_alloc&) {
        throw;
    } catch (const std::exception& e) {
        throw SlamError(doing() + ": " + plainMessage(e.what()), field);
    }
}

void checkReadable(const std::string& role, const std::string& path) {
    if (path.empty()) return;
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) throw SlamError(role + " not found: " + path, path);
    if (!std::ifstream(path, std::ios::binary))
        throw SlamError("cannot read the " + role + " " + path, path);
}

struct ScanStamp {
    double t;
    std::optional<Pose2D> odometry;
};

// The 2D scans of one step.
std::size_t scanCount(const IcpSlamStep& step) {
    if (step.observation) return IS_CLASS(*step.observation, CObservation2DRangeScan) ? 1 : 0;
    std::size_t n = 0;
    for (const auto& o : *step.frame) n += IS_CLASS(*o, CObservation2DRangeScan) ? 1 : 0;
    return n;
}

// IcpSlamOptions::skip_scans: true for every step until the first K scans have gone by.
class StartSkipper {
  public:
    explicit StartSkipper(std::size_t k) : left_(k) {}
    bool skip(const IcpSlamStep& step) {
        if (left_ == 0) return false;
        const std::size_t n = scanCount(step);
        skipped_ += n;
        left_ -= std::min(left_, n);
        return true;
    }
    std::size_t skipped() const { return skipped_; }

  private:
    std::size_t left_, skipped_ = 0;
};

// Every 2D scan of the log as the real run meets it (icp-slam's steps, after the skipped
// start), with its entry's odometry: what the pre-passes that match a drop rate read.
template <class Fn>
void forEachRunScan(const std::string& rawlog, const SourceOptions& options, std::size_t skip_scans,
                    Fn&& fn) {
    auto source = openLog(rawlog, options);
    IcpSlamSteps steps;
    IcpSlamStep step;
    StartSkipper skipper(skip_scans);
    SourceEntry e;
    while (nextEntry(*source, e)) {
        throwIfCancelled();
        if (!steps.feed(e, step) || skipper.skip(step)) continue;
        auto visit = [&](const mrpt::obs::CObservation::Ptr& o) {
            if (auto scan = std::dynamic_pointer_cast<CObservation2DRangeScan>(o))
                fn(scan, e.odometry);
        };
        if (step.observation)
            visit(step.observation);
        else
            for (const auto& o : *step.frame) visit(o);
    }
}

// Timestamps and odometry of every scan after the skipped start (for matching the odometry
// baseline's drop rate to a target before the real run); a non-finite odometry is unknown
// (kfd::checkOdometry, the door's rule).
std::vector<ScanStamp> scanOdometry(const std::string& rawlog, const SourceOptions& options,
                                    std::size_t skip_scans, bool laser_only) {
    std::vector<ScanStamp> out;
    forEachRunScan(rawlog, options, skip_scans,
                   [&](const CObservation2DRangeScan::Ptr& scan, std::optional<Pose2D> odo) {
                       if (laser_only) odo.reset();
                       checkOdometry(odo);
                       out.push_back({stampOf(*scan), odo});
                   });
    return out;
}

// The drop rate (%) of a pre-filter over the log, as the real run would see it (the same
// skipped start, the same door, odometry or none): the pre-filter alone, no ICP. With the
// denoise key next_scan a kept scan may come back pending (its keep decision is final): it is
// kept alive until the door finishes it, and the counters are complete after finish().
double pipelineDropPct(const std::string& rawlog, const SourceOptions& options,
                       const Pipeline::Params& pipeline, std::size_t skip_scans, bool laser_only) {
    StreamFilter filter(pipeline, {}, /*one_scan_latency=*/true);
    filter.setLaserOnly(laser_only);
    std::vector<CObservation2DRangeScan::Ptr> held;  // pending in the door (one per sensor)
    const auto release = [&] {
        StreamResult done;
        while (filter.takeFinished(done))
            held.erase(std::remove_if(held.begin(), held.end(),
                                      [&](const auto& p) { return p.get() == done.scan; }),
                       held.end());
    };
    forEachRunScan(rawlog, options, skip_scans,
                   [&](const CObservation2DRangeScan::Ptr& scan, std::optional<Pose2D> odo) {
                       if (filter.process(*scan, odo).pending) held.push_back(scan);
                       release();
                   });
    filter.finish();
    release();
    return filter.counters().notKeptPercent();
}

double dropPct(const std::vector<ScanStamp>& scans, const MotionFilter::Params& p) {
    MotionFilter f(p);
    std::size_t dropped = 0;
    for (const auto& s : scans) dropped += f.keep(s.t, s.odometry) ? 0 : 1;
    return scans.empty() ? 0.0 : 100.0 * static_cast<double>(dropped) / scans.size();
}

// Bisection on D (angle = 30 deg per metre of D): the drop rate grows with D.
MotionFilter::Params motionParamsForDropRate(const std::vector<ScanStamp>& scans,
                                             double target_pct) {
    MotionFilter::Params p;
    p.max_interval_s = 0.0;
    double lo = 0.0, hi = 5.0;
    for (int it = 0; it < 50; ++it) {
        const double mid = 0.5 * (lo + hi);
        p.max_distance_m = mid;
        p.max_angle_deg = 30.0 * mid;
        if (dropPct(scans, p) < target_pct)
            lo = mid;
        else
            hi = mid;
    }
    p.max_distance_m = hi;
    p.max_angle_deg = 30.0 * hi;
    return p;
}

// One kfd-icp-slam run, as steps: prepare (configuration, paths, pre-filter, pre-pass, ground
// truth), the map builder, the output files, the loop over icp-slam's steps, evaluate.
class Run {
  public:
    explicit Run(const IcpSlamOptions& o) : opts_(o), sum_(res_.summary) {}

    IcpSlamResult execute() {
        const auto wall0 = std::chrono::steady_clock::now();
        const std::clock_t cpu0 = std::clock();
        checkOptions();
        prepare();
        matchDropRate();
        readGroundTruth();
        StreamFilter prefilter(sum_.pipeline, {}, /*one_scan_latency=*/true);  // next_scan
        prefilter.setLaserOnly(opts_.laser_only);
        prefilter_ = &prefilter;
        initBuilder();
        openOutputs();
        loop();
        closeOutputs();
        evaluate();
        sum_.cpu_s_total = static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC;
        sum_.wall_s_total =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
        return std::move(res_);
    }

  private:
    void checkOptions();
    void prepare();
    void matchDropRate();
    void readGroundTruth();
    void initBuilder();
    void openOutputs();
    void loop();
    // A step in two phases. The pre-filter phase (prefilterStep: the door for its scans) may
    // leave a kept scan pending (the denoise key next_scan); the step then waits in waiting_,
    // and the steps after it behind it, until the door finishes that scan (the sensor's next
    // scan, or finish() at the end of the log). The builder phase (runStep: the map builder,
    // its verdict, the re-match, the step's outputs) runs for the waiting steps in input order
    // once nothing before them is pending. Without next_scan nothing is pending: every step
    // runs its builder phase right after its pre-filter phase, as before.
    struct DoorScan {
        CObservation2DRangeScan::Ptr scan;  // kept alive (and unchanged) while pending
        bool keep = false, pending = false;
        ScanSkipReason skipped = ScanSkipReason::None;
        ScanRecord record;  // final once the door finished it
    };
    struct WaitingStep {
        IcpSlamStep step;
        std::vector<DoorScan> scans;  // the step's 2D scans, in the step's order
        std::size_t pending = 0;      // of them, still pending in the door
    };
    std::deque<WaitingStep> waiting_;  // oldest first
    void prefilterStep(const IcpSlamStep& step, const SourceEntry& e);
    void collectFinished();
    void runReadySteps();
    void runStep(WaitingStep& w);
    void step(WaitingStep& w);
    template <class Process>
    void timed(Process&& process);
    template <class Process>
    void match(bool after_drops, Process&& process);
    void feedOdometry(const mrpt::poses::CPose2D& odometry);
    void rematch(const IcpSlamStep& step);
    bool toMapFrame(mrpt::obs::CObservationOdometry& odo);
    bool admitScan(DoorScan& d);
    mrpt::obs::CActionCollection* actionFor(const IcpSlamStep& step);
    void writeStep(double builder_ms);
    void closeOutputs();
    void evaluate();

    const IcpSlamOptions& opts_;
    IcpSlamResult res_;
    IcpSlamSummary& sum_;
    std::optional<mrpt::config::CConfigFile> cfg_;
    Pipeline::Params kfd_params_;  // [KFD], or kfd's defaults
    std::vector<Relation> relations_;
    StreamFilter* prefilter_ = nullptr;
    mrpt::slam::CMetricMapBuilderICP builder_;
    std::size_t rawlog_offset_ = 0;
    IcpSlamLogParams log_params_;      // [MappingApplication]'s output keys
    std::optional<IcpSlamLogs> logs_;  // icp-slam's files
    ScanCsvWriter csv_;                // scans.csv
    std::unique_ptr<Source> source_;
    double builder_s_ = 0.0;
    std::size_t step_no_ = 0;
    std::vector<ScanRecord> step_scans_;        // the scans of the current step, in order
    mrpt::obs::CActionCollection no_odometry_;  // laser_only: what the builder gets (empty)
    mrpt::obs::CActionCollection finite_actions_;
    bool origin_set_ = false;  // the first absolute odometry set res_.map_origin
    // ICP's correction of the current step, from the builder's log (onBuilderLog).
    void onBuilderLog(std::string_view msg);
    void noteIcp();
    enum class Verdict { Accepted, Rejected, GapCheckFailed };
    Verdict countCorrection();
    void recordVerdict();
    std::optional<double> step_goodness_;
    bool step_rejected_ = false;
    std::vector<double> goodness_;  // every correction's
    std::size_t rejected_streak_ = 0;
    double streak_start_ = 0.0;
    // After ICP rejected a correction, every scan goes to the map builder until it accepts one
    // again: the pre-filter's drops never widen the gap a struggling ICP has to bridge.
    bool recovering_ = false;
    std::size_t kept_for_recovery_ = 0;
    // Re-matching (rematch()): the scans the pre-filter dropped since ICP last accepted a
    // correction, each with the odometry the map builder had then; after a rejected correction
    // they go through ICP in order, then the rejected scan again. Their scans.csv rows wait in
    // pending_ (from the first held scan on) until ICP accepts a correction or they are
    // replayed.
    struct Held {
        CObservation2DRangeScan::Ptr scan;
        std::optional<mrpt::poses::CPose2D> odometry;  // the builder's, when it had one
        std::size_t row;                               // its entry in pending_
    };
    struct PendingRow {
        ScanRecord record;
        Pose2D pose;
        std::size_t trajectory_index;
    };
    std::vector<Held> held_;
    std::size_t held_this_step_ = 0;  // held_ entries added by the current step
    std::vector<PendingRow> pending_;
    void flushPending();
    // The odometry the map builder last got (MRPT's CMetricMapBuilderICP accumulates the
    // actions' pose changes, or takes an odometry observation as it is), and its stamp.
    std::optional<mrpt::poses::CPose2D> builder_odometry_;
    mrpt::Clock::time_point builder_odometry_t_{};
    std::size_t rematches_ = 0, rematches_recovered_ = 0, kept_for_rematch_ = 0;
    // The gap check (kfd/slam/gap_check.h): a correction across scans the pre-filter dropped
    // must reach a share of the log's recent median goodness, else it is rejected (MRPT's own
    // test, with a raised minimum) and re-matched.
    double min_goodness_ = 0.4;  // the configuration's minICPgoodnessToAccept
    std::optional<GapCheck> gap_check_;
};

// MRPT's map builder says how each ICP correction went only in its log: "Fit:%.1f%%" when
// accepted, "Ignoring ICP of low quality: X" (X in %) when rejected.
void Run::onBuilderLog(std::string_view msg) {
    const auto number_after = [&](std::string_view key) -> std::optional<double> {
        const auto at = msg.find(key);
        if (at == std::string_view::npos) return std::nullopt;
        const std::string rest(msg.substr(at + key.size(), 32));
        char* end = nullptr;
        const double v = std::strtod(rest.c_str(), &end);
        if (end == rest.c_str() || !std::isfinite(v)) return std::nullopt;
        return v / 100.0;
    };
    if (const auto fit = number_after("Fit:")) {
        step_goodness_ = *fit;
        step_rejected_ = false;
    } else if (const auto low = number_after("Ignoring ICP of low quality:")) {
        step_goodness_ = *low;
        step_rejected_ = true;
    }
}

// The step's correction, if ICP ran: counted, and a streak of rejections is a suspected lost
// track (its first rejection's stamp).
void Run::noteIcp() {
    if (!step_goodness_) return;
    const double stamp = step_scans_.empty() ? 0.0 : stampForOutput(step_scans_.back().stamp);
    switch (countCorrection()) {
        case Verdict::Accepted:
            rejected_streak_ = 0;
            held_.clear();  // nothing to re-match before an accepted correction
            break;
        case Verdict::Rejected:
            if (rejected_streak_++ == 0) streak_start_ = stamp;
            if (rejected_streak_ == kLostTrackRejections)
                sum_.lost_track_stamps.push_back(streak_start_);
            break;
        case Verdict::GapCheckFailed:  // re-matched (rematch()), not a rejection of the SLAM's
            break;
    }
    recordVerdict();
}

// A correction that ran (step_goodness_), counted: accepted (its goodness joins the gap
// check's), rejected by the SLAM's own minimum (icp_rejected), or rejected by the gap check
// only (gap_checks_failed: goodness above the configuration's minimum).
Run::Verdict Run::countCorrection() {
    ++sum_.icp_runs;
    goodness_.push_back(*step_goodness_);
    if (!step_rejected_) {
        gap_check_->accepted(*step_goodness_);
        return Verdict::Accepted;
    }
    if (*step_goodness_ > min_goodness_) {
        ++sum_.gap_checks_failed;
        return Verdict::GapCheckFailed;
    }
    ++sum_.icp_rejected;
    return Verdict::Rejected;
}

// The step's verdict on its kept scans' records; a rejection starts the recovery.
void Run::recordVerdict() {
    recovering_ = step_rejected_;
    for (ScanRecord& s : step_scans_)
        if (s.kept) {
            s.icp_goodness = *step_goodness_;
            s.icp_rejected = step_rejected_;
        }
    step_goodness_.reset();
}

// Options that contradict each other, before anything is read.
void Run::checkOptions() {
    const bool matchable =
        opts_.mode == PrefilterMode::Odometry || opts_.mode == PrefilterMode::Decimate;
    if ((opts_.odometry_target_drop_pct || opts_.match_drop_of) && !matchable)
        throw SlamOptionError(
            std::string("a matched drop rate (--match-drop, --match-drop-of) applies to --mode "
                        "odometry or decimate only (not ") +
                toString(opts_.mode) + ")",
            "mode");
    if (opts_.odometry_target_drop_pct && opts_.match_drop_of)
        throw SlamOptionError("give --match-drop or --match-drop-of, not both", "match_drop_of");
}

// The configuration, the paths (every input readable, no output aliases one) and the pre-filter.
void Run::prepare() {
    sum_.mode = opts_.mode;
    std::error_code ec;
    if (!fs::is_regular_file(opts_.config_file, ec))
        throw SlamError("configuration file not found: " + opts_.config_file);
    cfg_.emplace(opts_.config_file);
    sum_.rawlog =
        !opts_.rawlog.empty() ? opts_.rawlog : cfg_->read_string(kSect, "rawlog_file", "");
    sum_.output_dir = !opts_.output_dir.empty() ? opts_.output_dir
                                                : cfg_->read_string(kSect, "logOutput_dir", "");
    if (sum_.rawlog.empty()) throw SlamError("no rawlog given (option or rawlog_file)");
    if (!fs::is_regular_file(sum_.rawlog, ec)) throw SlamError("rawlog not found: " + sum_.rawlog);
    if (sum_.output_dir.empty())
        throw SlamError("no output folder given (option or logOutput_dir)");
    checkReadable("rawlog", sum_.rawlog);
    checkReadable("relations file", opts_.relations);
    checkReadable("ground-truth trajectory", opts_.ground_truth_tum);
    const std::vector<NamedPath> inputs = {{"configuration", opts_.config_file},
                                           {"rawlog", sum_.rawlog},
                                           {"relations file", opts_.relations},
                                           {"ground-truth trajectory", opts_.ground_truth_tum}};
    std::vector<NamedPath> outputs;
    for (const char* name : kIcpSlamOutputFiles)
        outputs.push_back(
            {std::string("output ") + name, (fs::path(sum_.output_dir) / name).string()});
    // icp-slam's numbered files: those the output folder holds already would be replaced
    if (fs::is_directory(sum_.output_dir, ec))
        for (const auto& entry : fs::directory_iterator(sum_.output_dir, ec))
            if (isIcpSlamNumberedOutput(entry.path().filename().string()))
                outputs.push_back(
                    {"output " + entry.path().filename().string(), entry.path().string()});
    checkOutputPaths(inputs, outputs);
    for (const NamedPath& in : inputs)
        if (samePath(sum_.output_dir, in.path))
            throw PathError(
                "the output folder " + sum_.output_dir + " is the " + in.role + " " + in.path,
                sum_.output_dir);

    log_params_ = IcpSlamLogParams::fromConfig(*cfg_, kSect, sum_.notices);
    // Pre-filter configuration: [KFD] when present, else kfd's defaults (share/kfd/default.ini).
    kfd_params_ = cfg_->sectionExists("KFD") ? loadIni(*cfg_, "KFD") : kfdDefaults();
    // The SLAM's localisation gate: ICP corrects the pose only after this much odometry since
    // its last correction. kfd's keyframe guards (those that are on) never let more pass
    // between kept scans, so a drop never skips the scan the gate would have matched.
    {
        auto& kf = kfd_params_.get<KeyframeStage>();
        const double gate_m = cfg_->read_double(kSect, "localizationLinDistance", 0.2);
        const double gate_deg = cfg_->read_double(kSect, "localizationAngDistance", 5.0);
        if (gate_m > 0.0 && kf.max_translation_m > gate_m) kf.max_translation_m = gate_m;
        if (gate_deg > 0.0 && kf.max_rotation_deg > gate_deg) kf.max_rotation_deg = gate_deg;
        sum_.guard_translation_m = kf.max_translation_m;
        sum_.guard_rotation_deg = kf.max_rotation_deg;
    }
    sum_.pipeline = pipelineForMode(opts_.mode, kfd_params_);
    sum_.laser_only = opts_.laser_only;
    if (!(opts_.split_seconds >= 0.0) || !std::isfinite(opts_.split_seconds))
        throw SlamError("the local/long split must be finite and >= 0 s (got " +
                            std::to_string(opts_.split_seconds) + ")",
                        "split_seconds");
    sum_.split_seconds = opts_.split_seconds;
    if (!(opts_.relations_max_dt >= 0.0) || !std::isfinite(opts_.relations_max_dt))
        throw SlamError("the stamp matching tolerance must be finite and >= 0 (got " +
                            std::to_string(opts_.relations_max_dt) + " s)",
                        "relations_max_dt");
}

// Odometry and decimate modes with a target: the drop rate to match (given, or measured by a
// pre-pass of another mode's pre-filter), then the thresholds or share that reach it.
void Run::matchDropRate() {
    if (opts_.match_drop_of) {
        const std::clock_t m0 = std::clock();
        sum_.target_drop_pct = pipelineDropPct(sum_.rawlog, opts_.source,
                                               pipelineForMode(*opts_.match_drop_of, kfd_params_),
                                               opts_.skip_scans, opts_.laser_only);
        sum_.cpu_s_match = static_cast<double>(std::clock() - m0) / CLOCKS_PER_SEC;
    } else if (opts_.odometry_target_drop_pct) {
        sum_.target_drop_pct = *opts_.odometry_target_drop_pct;
    }
    if (!sum_.target_drop_pct) return;
    const double target = *sum_.target_drop_pct;
    if (!(target >= 0.0 && target < 100.0))
        throw SlamError("the target drop rate must be in [0, 100)");
    if (opts_.mode == PrefilterMode::Odometry)
        sum_.pipeline.get<MotionStage>() = motionParamsForDropRate(
            scanOdometry(sum_.rawlog, opts_.source, opts_.skip_scans, opts_.laser_only), target);
    else
        sum_.pipeline.get<DecimateStage>().keep_fraction = 1.0 - target / 100.0;
}

// The relations and the ground truth, read before the run: a bad file fails at once.
void Run::readGroundTruth() {
    if (!opts_.relations.empty()) {
        relations_ = readRelations(opts_.relations);  // EvalError
        if (relations_.empty())
            throw SlamError("no relation in " + opts_.relations, opts_.relations);
    }
    if (!opts_.ground_truth_tum.empty()) {
        res_.ground_truth = readTum(opts_.ground_truth_tum);  // EvalError
        sortByTime(res_.ground_truth);
    }
}

// The map builder, configured exactly as icp-slam does.
void Run::initBuilder() {
    callMrpt(
        [&] {
            builder_.setVerbosityLevel(mrpt::system::LVL_ERROR);
            // ICP's goodness per correction reaches kfd through the log (onBuilderLog).
            builder_.setVerbosityLevelForCallbacks(mrpt::system::LVL_INFO);
            builder_.logRegisterCallback([this](std::string_view msg, mrpt::system::VerbosityLevel,
                                                std::string_view,
                                                mrpt::Clock::time_point) { onBuilderLog(msg); });
            builder_.ICP_options.loadFromConfigFile(*cfg_, kSect);
            min_goodness_ = builder_.ICP_options.minICPgoodnessToAccept;
            gap_check_.emplace(min_goodness_);
            builder_.ICP_params.loadFromConfigFile(*cfg_, "ICP");
            builder_.initialize();
            builder_.options.alwaysInsertByClass.fromString(
                cfg_->read_string(kSect, "alwaysInsertByClass", ""));
        },
        [&] { return "the configuration " + opts_.config_file + " ([" + kSect + "], [ICP])"; },
        opts_.config_file);
    rawlog_offset_ =
        static_cast<std::size_t>(std::max(0, cfg_->read_int(kSect, "rawlog_offset", 0)));
}

// Everything is written into a staging folder; writeIcpSlamReport() (or
// result.output->commit()) moves it into place, and on failure it is removed.
void Run::openOutputs() {
    res_.output = std::make_shared<StagedOutputFolder>(sum_.output_dir);
    // Every file through kfd's checked writers: a failed write is a WriteError (ScanCsvError for
    // scans.csv) naming the file's final name and the reason.
    const StagedOutputFolder& out = *res_.output;
    logs_.emplace(out, log_params_);
    csv_.open((out.path() / "scans.csv").string(), out.finalName("scans.csv"));
    source_ = openLog(sum_.rawlog, opts_.source);
}

// icp-slam's steps over the log, after rawlog_offset and the skipped start.
void Run::loop() {
    const double total_bytes =
        static_cast<double>(std::max<std::uint64_t>(1, source_->bytesTotal()));
    auto progress = [&](double fraction) {
        const ScanCounters& c = prefilter_->counters();
        opts_.on_progress({sum_.entries, c.scans_in, c.scans_kept, fraction});
    };
    SourceEntry e;
    IcpSlamSteps steps;
    IcpSlamStep st;
    StartSkipper skipper(opts_.skip_scans);
    while (nextEntry(*source_, e)) {
        throwIfCancelled();
        if (!steps.feed(e, st)) {
            e.forEachScan([&](const auto&) { ++sum_.scans_without_step; });
            continue;
        }
        if (e.objects_read < rawlog_offset_) {
            sum_.scans_before_offset += scanCount(st);
            continue;
        }
        if (skipper.skip(st)) continue;
        prefilterStep(st, e);
        const std::size_t steps_before = step_no_;
        runReadySteps();
        if (opts_.on_progress && step_no_ / 500 != steps_before / 500)
            progress(static_cast<double>(source_->bytesRead()) / total_bytes);
    }
    // The end of the log: the door finishes the scans it holds (next_scan), and the steps
    // waiting for them run; the door's counters are then complete.
    prefilter_->finish();
    collectFinished();
    runReadySteps();
    if (!waiting_.empty())  // the door finished every scan it held: a broken invariant
        throw std::logic_error("kfd-icp-slam: a step still waits for the pre-filter at the end");
    if (sum_.entries == 0 && skipper.skipped() == 0)
        throw SlamError("no entries in " + sum_.rawlog + ": not a rawlog?", sum_.rawlog);
    sum_.scans_skipped_start = skipper.skipped();
    sum_.source = source_->counters();
    // No scan reached the pre-filter's stages: an error, not a run without a map.
    std::string none = noUsableScan(prefilter_->counters(), sum_.source, sum_.rawlog);
    if (!none.empty() && prefilter_->counters().scans_in == 0 && sum_.scans_skipped_start)
        none += " after the " + std::to_string(sum_.scans_skipped_start) +
                " skipped at its start (skip_scans = " + std::to_string(opts_.skip_scans) + ")";
    if (!none.empty()) throw SlamError(none, sum_.rawlog);
    if (opts_.on_progress) progress(1.0);
}

// A call into the map builder, timed; what it throws names the step, its last scan's stamp
// and the log.
template <class Process>
void Run::timed(Process&& process) {
    const auto t0 = std::chrono::steady_clock::now();
    callMrpt(
        process,
        [&] {
            char where[96];
            std::snprintf(where, sizeof(where), "MRPT's ICP map builder failed at step %zu",
                          step_no_);
            std::string doing = where;
            if (!step_scans_.empty()) {
                std::snprintf(where, sizeof(where), " (scan at t = %.6f s)",
                              step_scans_.back().stamp);
                doing += where;
            }
            return doing + " of " + sum_.rawlog;
        },
        sum_.rawlog);
    builder_s_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// A call into the map builder with the step's scans; after drops (scans held since ICP's last
// accepted correction, from earlier steps) under the gap check's minimum for that one call.
template <class Process>
void Run::match(bool after_drops, Process&& process) {
    if (after_drops) builder_.ICP_options.minICPgoodnessToAccept = gap_check_->minimum();
    timed(process);
    builder_.ICP_options.minICPgoodnessToAccept = min_goodness_;
}

// A step's pre-filter phase: its scans through the door (every mode, `none` included), in
// order; the step waits in waiting_ for its builder phase. The scans the door finishes now
// (held before, next_scan) go to their waiting steps.
void Run::prefilterStep(const IcpSlamStep& st, const SourceEntry& e) {
    waiting_.push_back(WaitingStep{st, {}, 0});
    WaitingStep& w = waiting_.back();  // a deque: push_back keeps references
    const auto door = [&](const mrpt::obs::CObservation::Ptr& o) {
        auto scan = std::dynamic_pointer_cast<CObservation2DRangeScan>(o);
        if (!scan) return;
        StreamResult r = prefilter_->process(*scan, e.odometry);
        w.scans.push_back({scan, r.keep, r.pending, r.skipped, std::move(r.record)});
        w.pending += r.pending ? 1 : 0;
        collectFinished();  // e.g. the sensor's scan before this one
    };
    if (st.observation)
        door(st.observation);
    else
        for (const auto& o : *st.frame) door(o);
}

// The scans the door finished (pending before): their final decision and record, in their
// waiting step.
void Run::collectFinished() {
    StreamResult done;
    while (prefilter_->takeFinished(done)) {
        for (WaitingStep& w : waiting_)
            for (DoorScan& d : w.scans)
                if (d.pending && d.scan.get() == done.scan) {
                    d.pending = false;
                    d.keep = done.keep;
                    d.record = std::move(done.record);
                    --w.pending;
                }
    }
}

// The builder phase of the waiting steps, in input order, up to the first one still pending.
void Run::runReadySteps() {
    while (!waiting_.empty() && waiting_.front().pending == 0) {
        WaitingStep w = std::move(waiting_.front());
        waiting_.pop_front();
        runStep(w);
    }
}

// A step's builder phase: the map builder, ICP's verdict, a re-match, the step's outputs.
void Run::runStep(WaitingStep& w) {
    const IcpSlamStep& st = w.step;
    const double builder_s0 = builder_s_;
    logs_->beginStep(st.observation, st.action.get(), st.frame.get());
    step(w);
    noteIcp();
    rematch(st);
    writeStep(1e3 * (builder_s_ - builder_s0));
    ++step_no_;
    ++sum_.entries;
}

// One step's scans as the door decided them (admitScan), the kept ones and the odometry to the
// map builder.
void Run::step(WaitingStep& w) {
    step_scans_.clear();
    held_this_step_ = 0;
    IcpSlamStep& st = w.step;
    auto next = w.scans.begin();  // the step's scans, in the order of the pre-filter phase
    if (st.observation) {
        bool process = true;
        if (dynamic_cast<CObservation2DRangeScan*>(st.observation.get())) {
            process = admitScan(*next++);
        } else if (auto* odo =
                       dynamic_cast<mrpt::obs::CObservationOdometry*>(st.observation.get())) {
            process = !opts_.laser_only && toMapFrame(*odo);
            if (process) {
                builder_odometry_ = mrpt::poses::CPose2D(odo->odometry);
                builder_odometry_t_ = odo->timestamp;
            }
        }
        if (process)
            match(!held_.empty() && !held_this_step_,
                  [&] { builder_.processObservation(st.observation); });
        return;
    }
    for (auto it = st.frame->begin(); it != st.frame->end();) {
        if (dynamic_cast<CObservation2DRangeScan*>(it->get()) && !admitScan(*next++))
            it = st.frame->erase(it);
        else
            ++it;
    }
    // odometry kept even if the frame is empty
    mrpt::obs::CActionCollection* action = actionFor(st);
    if (auto mv = action->getBestMovementEstimation(); mv && mv->poseChange) {
        // what CMetricMapBuilderICP::processActionObservation accumulates
        builder_odometry_ =
            builder_odometry_.value_or(mrpt::poses::CPose2D()) + mv->poseChange->getMeanVal();
        builder_odometry_t_ = mv->timestamp;
    }
    for (std::size_t k = held_.size() - held_this_step_; k < held_.size(); ++k)
        held_[k].odometry = builder_odometry_;
    match(held_.size() > held_this_step_ && scanCount(st),
          [&] { builder_.processActionObservation(*action, *st.frame); });
}

// An odometry reading for the map builder during a re-match: stamped just after the last one
// (its pose estimator wants increasing stamps; without velocities it does not extrapolate).
void Run::feedOdometry(const mrpt::poses::CPose2D& odometry) {
    auto odo = std::make_shared<mrpt::obs::CObservationOdometry>();
    odo->odometry = odometry;
    builder_odometry_t_ += std::chrono::microseconds(1);
    odo->timestamp = builder_odometry_t_;
    timed([&] { builder_.processObservation(odo); });
}

// After ICP rejected the step's correction: the scans dropped since its last accepted one go
// through ICP in their order, each from the odometry the builder had then, and the step's
// kept scans again from their own, so that ICP bridges the odometry in the log's own steps
// (MRPT's builder leaves its map and its last correction untouched by a rejection). Their
// rows say "icp_rematch". No replay of a replay: held_ is emptied either way.
void Run::rematch(const IcpSlamStep& st) {
    if (!recovering_ || held_.empty()) return;
    ++rematches_;
    const auto pose_now = [&] {
        const auto m = builder_.getCurrentPoseEstimation()->getMeanVal();
        return Pose2D{m.x() + res_.map_origin.x, m.y() + res_.map_origin.y, m.yaw()};
    };
    bool corrected = false;  // did a replayed scan move the pose?
    for (const Held& h : held_) {
        if (h.row >= pending_.size()) break;  // the step's own (a frame of several scans)
        if (h.odometry) feedOdometry(*h.odometry);
        step_goodness_.reset();
        timed([&] { builder_.processObservation(h.scan); });
        PendingRow& row = pending_[h.row];
        row.record.kept = true;
        row.record.reason = "icp_rematch";
        if (step_goodness_) {
            const bool accepted = countCorrection() == Verdict::Accepted;
            corrected = corrected || accepted;
            row.record.icp_goodness = *step_goodness_;
            row.record.icp_rejected = step_rejected_;
        }
        row.pose = pose_now();
        res_.trajectory[row.trajectory_index].pose = row.pose;
        res_.keyframes.push_back(row.trajectory_index);
        ++kept_for_rematch_;
    }
    held_.clear();
    // Nothing corrected (every replay rejected, or under the SLAM's gate): the same prior on
    // the same map would give the same fit; the scan stays rejected and the recovery goes on.
    if (!corrected) return;
    if (builder_odometry_) feedOdometry(*builder_odometry_);
    step_goodness_.reset();
    if (st.observation)
        timed([&] { builder_.processObservation(st.observation); });
    else
        for (const auto& o : *st.frame)
            if (IS_CLASS(*o, CObservation2DRangeScan))
                timed([&] { builder_.processObservation(o); });
    if (!step_goodness_) return;
    if (countCorrection() == Verdict::Accepted) {
        ++rematches_recovered_;
        rejected_streak_ = 0;
    }
    recordVerdict();
}

// An absolute odometry reading as the map builder gets it: in the local frame
// (IcpSlamResult::map_origin), which the first finite reading sets. False when not finite.
bool Run::toMapFrame(mrpt::obs::CObservationOdometry& odo) {
    auto& p = odo.odometry;
    if (!finitePose(p.x(), p.y(), p.phi())) return false;
    if (!origin_set_) {
        origin_set_ = true;
        if (std::hypot(p.x(), p.y()) > kLocalFrameM)
            res_.map_origin = Pose2D{std::round(p.x()), std::round(p.y()), 0.0};
    }
    p.x(p.x() - res_.map_origin.x);
    p.y(p.y() - res_.map_origin.y);
    return true;
}

// A scan as the door decided it (final); true when it goes on to ICP. Its record waits for the
// step's pose. Applied in the step's builder phase: the recovery reads the builder's state.
bool Run::admitScan(DoorScan& r) {
    const CObservation2DRangeScan::Ptr& scan = r.scan;
    if (!r.keep && recovering_ && r.skipped == ScanSkipReason::None) {
        // Dropped by the pre-filter while ICP is recovering from a rejected correction: it
        // goes to the map builder all the same (as cleaned by the stages that ran).
        r.keep = r.record.kept = true;
        r.record.reason = "icp_recovery";
        ++kept_for_recovery_;
    }
    if (!r.keep && r.skipped == ScanSkipReason::None) {
        // held for a re-match (a frame's odometry follows with its action: step())
        if (held_.size() == kMaxHeld) {  // a long gap: the oldest rows go out, none held
            held_.clear();
            flushPending();
        }
        held_.push_back({scan, builder_odometry_, pending_.size() + step_scans_.size()});
        ++held_this_step_;
    }
    step_scans_.push_back(std::move(r.record));
    return r.keep;
}

// The step's odometry action as the builder gets it: none with laser_only; a non-finite
// movement left out (the map builder then matches without a motion prior).
mrpt::obs::CActionCollection* Run::actionFor(const IcpSlamStep& st) {
    mrpt::obs::CActionCollection* action = opts_.laser_only ? &no_odometry_ : st.action.get();
    if (auto mv = action->getBestMovementEstimation()) {
        const auto d = mv->rawOdometryIncrementReading;
        const auto m = mv->poseChange ? mv->poseChange->getMeanVal() : d;
        if (!finitePose(d.x(), d.y(), d.phi()) || !finitePose(m.x(), m.y(), m.phi())) {
            finite_actions_ = mrpt::obs::CActionCollection();
            for (std::size_t k = 0; k < action->size(); ++k)
                if (action->get(k).get() != mv.get()) finite_actions_.insert(*action->get(k));
            action = &finite_actions_;
        }
    }
    return action;
}

// The step's pose (icp-slam's files) and, for each of its scans, the trajectory, odometry,
// keyframe and corridor entries and the scans.csv row.
void Run::writeStep(double builder_ms) {
    const auto local = builder_.getCurrentPoseEstimation()->getMeanVal();
    const mrpt::poses::CPose3D pose(local.x() + res_.map_origin.x, local.y() + res_.map_origin.y,
                                    local.z(), local.yaw(), local.pitch(), local.roll());
    logs_->endStep(step_no_, builder_, builder_ms, pose, res_.map_origin);
    const Pose2D p{pose.x(), pose.y(), pose.yaw()};
    Trajectory& traj = res_.trajectory;
    for (const ScanRecord& s : step_scans_) {
        if (s.kept) res_.keyframes.push_back(traj.size());
        if (s.corridor) res_.corridor.push_back(traj.size());
        const double t = stampForOutput(s.stamp);
        if (s.odometry) res_.odometry.push_back(StampedPose{t, *s.odometry});
        traj.push_back(StampedPose{t, p});
        pending_.push_back({s, p, traj.size() - 1});
    }
    if (held_.empty()) flushPending();
}

// The rows waiting for a possible re-match, to scans.csv.
void Run::flushPending() {
    for (const PendingRow& row : pending_) csv_.write(row.record, row.pose);
    pending_.clear();
}

void Run::closeOutputs() {
    held_.clear();
    flushPending();
    std::sort(res_.keyframes.begin(), res_.keyframes.end());
    logs_->finish(builder_, res_.map_origin, opts_.write_map, sum_.notices);
    csv_.close();
    writeTum((res_.output->path() / "trajectory.tum").string(), res_.trajectory,
             res_.output->finalName("trajectory.tum"));
}

// The summary from the door's counters, the map, ATE and the relations error (local and long).
void Run::evaluate() {
    static_cast<ScanCounters&>(sum_) = prefilter_->counters();
    sum_.scans_kept += kept_for_recovery_;  // the door counted them as dropped
    sum_.scans_dropped -= kept_for_recovery_;
    sum_.scans_kept_for_recovery = kept_for_recovery_;
    sum_.scans_kept += kept_for_rematch_;
    sum_.scans_dropped -= kept_for_rematch_;
    sum_.scans_rematched = kept_for_rematch_;
    sum_.rematches = rematches_;
    sum_.rematches_recovered = rematches_recovered_;
    sum_.dropped_pct = sum_.notKeptPercent();
    const double scans_in = static_cast<double>(sum_.scans_in);
    sum_.prefilter_us_per_scan = sum_.scans_in ? 1e6 * sum_.filter_seconds / scans_in : 0;
    sum_.icp_ms_per_scan = sum_.scans_in ? 1e3 * builder_s_ / scans_in : 0;
    sum_.icp_ms_per_kept_scan =
        sum_.scans_kept ? 1e3 * builder_s_ / static_cast<double>(sum_.scans_kept) : 0;
    if (!goodness_.empty()) {
        std::vector<double> g = goodness_;
        std::nth_element(g.begin(), g.begin() + static_cast<std::ptrdiff_t>(g.size() / 2), g.end());
        sum_.icp_goodness_median = g[g.size() / 2];
    }
    if (opts_.write_map) {
        res_.map.emplace();
        builder_.getCurrentlyBuiltMap(*res_.map);
    }
    if (opts_.ground_truth_tum.empty() && relations_.empty()) return;
    Trajectory sorted = res_.trajectory;
    sortByTime(sorted);
    if (!opts_.ground_truth_tum.empty())
        sum_.ate_rmse = computeAte(sorted, res_.ground_truth, opts_.relations_max_dt).rmse;
    if (relations_.empty()) return;
    // EvalError when no relation matched (never a perfect 0.0)
    sum_.relations = evaluateRelations(sorted, relations_, opts_.relations_max_dt);
    sum_.relations_file = opts_.relations;
    // Local and long relations; a subset that is empty or matched nothing stays absent.
    const RelationsByLength split = splitRelations(relations_, opts_.split_seconds);
    sum_.relations_local_count = split.local.size();
    sum_.relations_long_count = split.far.size();
    auto subset = [&](const std::vector<Relation>& r) -> std::optional<RelationsError> {
        if (r.empty()) return std::nullopt;
        try {
            return evaluateRelations(sorted, r, opts_.relations_max_dt);
        } catch (const EvalError&) {
            return std::nullopt;  // none of this subset matched
        }
    };
    sum_.relations_local = subset(split.local);
    sum_.relations_long = subset(split.far);
}

}  // namespace

bool isIcpSlamNumberedOutput(const std::string& file_name) {
    for (const OutputNamePattern& p : kIcpSlamNumberedOutputs) {
        const std::string_view name(file_name), prefix(p.prefix), suffix(p.suffix);
        if (name.size() >= prefix.size() + suffix.size() &&
            name.substr(0, prefix.size()) == prefix &&
            name.substr(name.size() - suffix.size()) == suffix)
            return true;
    }
    return false;
}

IcpSlamResult IcpSlamRunner::run(const IcpSlamOptions& opts) { return Run(opts).execute(); }

}  // namespace kfd
