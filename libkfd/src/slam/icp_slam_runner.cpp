// kfd-icp-slam's run: prepare, the map builder, and the loop over icp-slam's steps with the door's
// two phases (a step waits while the pre-filter holds one of its scans: next_scan).
#include "icp_slam_run.h"

namespace kfd {
namespace icp_slam {
using mrpt::obs::CObservation2DRangeScan;
// The configuration, the paths (every input readable, no output aliases one) and the
// pre-filter: [KFD] when present, else kfd's defaults, its guards under the SLAM's gate.
void Run::prepare() {
    sum_.mode = opts_.mode;
    cfg_.emplace(checkConfigFile(opts_.config_file));
    resolvePaths(opts_, *cfg_, sum_);
    log_params_ = IcpSlamLogParams::fromConfig(*cfg_, kSect, sum_.notices);
    // Flat [KFD] keys (read for this release) are named with their new spelling in notices.
    kfd_params_ =
        cfg_->sectionExists("KFD") ? loadIni(*cfg_, "KFD", nullptr, &sum_.notices) : kfdDefaults();
    applySlamGate(*cfg_, kfd_params_, sum_);
    sum_.pipeline = pipelineForMode(opts_.mode, kfd_params_);
    tracking_ = sum_.pipeline.lists(TrackStage::kName);
    sum_.laser_only = opts_.laser_only;
    checkEvaluationOptions(opts_, sum_);
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
                                                std::string_view, mrpt::Clock::time_point) {
                if (icp_) icp_->onBuilderLog(msg);
            });
            builder_.ICP_options.loadFromConfigFile(*cfg_, kSect);
            icp_.emplace(builder_.ICP_options.minICPgoodnessToAccept);
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
        const std::size_t steps_before = step_no_;
        prefilterStep(st, e);
        if (opts_.on_progress && step_no_ / 500 != steps_before / 500)
            progress(static_cast<double>(source_->bytesRead()) / total_bytes);
    }
    // The end of the log: the door finishes the scans it holds (next_scan), and the steps
    // behind them run; the door's counters are then complete.
    prefilter_->finish();
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

// A step's pre-filter phase: its scans through the door (every mode, `none` included), in
// order; its builder phase runs when the door has finished them (at once without next_scan;
// the door keeps the steps in input order).
void Run::prefilterStep(const IcpSlamStep& st, const SourceEntry& e) {
    auto w = std::make_shared<DoorStep>(DoorStep{st, {}});
    const auto door = [&](const mrpt::obs::CObservation::Ptr& o) {
        auto scan = std::dynamic_pointer_cast<CObservation2DRangeScan>(o);
        if (!scan) return;
        const std::size_t k = w->scans.size();
        w->scans.push_back(DoorScan{scan, false, ScanSkipReason::None, ScanRecord{}});
        prefilter_->process(*scan, e.odometry, [w, k](StreamResult& r) {
            DoorScan& d = w->scans[k];
            d.keep = r.keep;
            d.skipped = r.skipped;
            d.record = std::move(r.record);
        });
    };
    if (st.observation)
        door(st.observation);
    else
        for (const auto& o : *st.frame) door(o);
    prefilter_->then([this, w] { runStep(*w); });
}

// A step's builder phase: the map builder, ICP's verdict, a re-match, the step's outputs.
void Run::runStep(DoorStep& w) {
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
void Run::step(DoorStep& w) {
    step_scans_.clear();
    rematch_this_step_ = 0;
    IcpSlamStep& st = w.step;
    auto next = w.scans.begin();  // the step's scans, in the order of the pre-filter phase
    if (st.observation) {
        bool process = true;
        if (dynamic_cast<CObservation2DRangeScan*>(st.observation.get())) {
            feedTrack(*next);
            process = admitScan(*next++);
        } else if (auto* odo =
                       dynamic_cast<mrpt::obs::CObservationOdometry*>(st.observation.get())) {
            process = !opts_.laser_only && !tracking_ && toMapFrame(*odo);
            if (process) {
                builder_odometry_ = mrpt::poses::CPose2D(odo->odometry);
                builder_odometry_t_ = odo->timestamp;
            }
        }
        if (process)
            match(!rematch_this_step_ && gapToBridge(0),
                  [&] { builder_.processObservation(st.observation); });
        return;
    }
    for (const DoorScan& d : w.scans) feedTrack(d);
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
    for (std::size_t k = rematch_.size() - rematch_this_step_; k < rematch_.size(); ++k)
        rematch_[k].odometry = builder_odometry_;
    match(gapToBridge(rematch_this_step_) && scanCount(st),
          [&] { builder_.processActionObservation(*action, *st.frame); });
}

// With the track stage: the scan's tracked pose (kept or dropped) is the map builder's
// odometry, stamped with the scan, so that a dropped scan's pose is the last correction plus
// the track and the next keyframe's ICP starts from where the scans say the robot is.
void Run::feedTrack(const DoorScan& d) {
    if (!tracking_) return;
    const TrackResult* t = d.record.report.find<TrackResult>();
    if (!t) return;  // not through the stages (unusable geometry)
    mrpt::obs::CObservationOdometry odo;
    odo.odometry = mrpt::poses::CPose2D(t->pose.x, t->pose.y, t->pose.phi);
    if (!toMapFrame(odo)) return;
    odo.timestamp = std::max(d.scan->timestamp, builder_odometry_t_ + std::chrono::microseconds(1));
    builder_odometry_ = odo.odometry;
    builder_odometry_t_ = odo.timestamp;
    timed([&] {
        builder_.processObservation(std::make_shared<mrpt::obs::CObservationOdometry>(odo));
    });
}

// Scans dropped since ICP's last accepted correction (those of the current step, `own`, left
// out) that the next correction has to bridge: every one without the tracker, the ones it
// could not align with it. The gap check applies then.
bool Run::gapToBridge(std::size_t own) const {
    if (rematch_.size() <= own) return false;
    const auto end = rematch_.end() - static_cast<std::ptrdiff_t>(own);
    return !tracking_ ||
           std::any_of(rematch_.begin(), end, [](const RematchScan& r) { return !r.tracked; });
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

// The step's odometry action as the builder gets it: none with laser_only; a non-finite
// movement left out (the map builder then matches without a motion prior).
mrpt::obs::CActionCollection* Run::actionFor(const IcpSlamStep& st) {
    mrpt::obs::CActionCollection* action =
        opts_.laser_only || tracking_ ? &no_odometry_ : st.action.get();
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

}  // namespace icp_slam

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

IcpSlamResult IcpSlamRunner::run(const IcpSlamOptions& opts) {
    return icp_slam::Run(opts).execute();
}

}  // namespace kfd
