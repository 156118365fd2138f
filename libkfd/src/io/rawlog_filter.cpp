#include "kfd/io/rawlog_filter.h"

#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/poses/CPose2D.h>
#include <mrpt/serialization/CArchive.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "kfd/os/cancel.h"
#include "kfd/os/output_paths.h"

#include "kfd/algorithms/scan_rate.h"
#include "kfd/io/carmen_writer.h"
#include "kfd/io/gz_output.h"
#include "kfd/io/open_source.h"
#include "kfd/io/ros2_writer.h"
#include "kfd/io/scan_csv.h"
#include "kfd/stages/denoise_result.h"
#include "kfd/stages/evidence_denoise_stage.h"

namespace kfd {
namespace {

namespace fs = std::filesystem;
using mrpt::obs::CActionCollection;
using mrpt::obs::CActionRobotMovement2D;
using mrpt::obs::CObservation2DRangeScan;
using mrpt::obs::CSensoryFrame;
using mrpt::poses::CPose2D;

// Runs fn; the errors of the sources, of the bag writer, of the stats file and of the outputs
// (SourceError, BagError, CarmenError, ScanCsvError, PathError, WriteError) come out as
// RawlogError, the class RawlogFilter reports (a RawlogError as it is). `field`: the path the
// error is about, when it is not the error's own (the output).
template <class Fn>
decltype(auto) asRawlogError(Fn&& fn, const std::string& field = {}) {
    try {
        return fn();
    } catch (const RawlogError&) {
        throw;
    } catch (const SourceError& e) {
        throw RawlogError(e.what(), field.empty() ? e.field() : field);
    } catch (const ScanCsvError& e) {
        throw RawlogError(e.what(), e.field());
    } catch (const PathError& e) {
        throw RawlogError(e.what(), e.field());
    } catch (const CarmenWriteError& e) {
        throw RawlogError(e.what(), e.field());
    }
}

// The output's format by its name; a PathError naming the formats for any other name.
bool isRos2(LogFormat f) { return f == LogFormat::Rosbag2 || f == LogFormat::Mcap; }
bool isBagLike(LogFormat f) { return f == LogFormat::Bag || isRos2(f); }

LogFormat outputFormat(const std::string& output) {
    if (hasExtension(output, ".bag")) return LogFormat::Bag;
    LogFormat ros2;
    if (ros2OutputFormat(output, ros2)) return ros2;
    if (isCarmenOutputName(output)) return LogFormat::Carmen;
    checkOutputName({"output", output}, {".rawlog"},
                    "kfd-filter writes .rawlog (an MRPT rawlog), .bag (a ROS 1 bag, for a ROS 1 "
                    "bag input), .db3 or .mcap (ROS 2, for any bag input), .clf or .log (a "
                    "CARMEN log; .clf.gz, .log.gz: gzip)");
    return LogFormat::Rawlog;
}

// One kfd-filter run, as steps: prepare (paths, formats, source), open the outputs, the loop
// over the log's entries, finish (the last carried odometry, close, commit, summary).
class Run {
  public:
    Run(const RawlogFilterOptions& o, RawlogFilterSummary& s)
        : opts_(o), sum_(s), filter_(o.pipeline, {}, true) {
        filter_.setLaserOnly(o.laser_only);
    }

    void execute() {
        const auto t0 = std::chrono::steady_clock::now();
        prepare();
        openOutputs();
        loop();
        finish();
        sum_.wall_seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        reportProgress(source_->bytesTotal());
    }

  private:
    void prepare();
    void openOutputs();
    void loop();
    void finish();
    void handleEntry(const SourceEntry& e);
    void handleObservation(const SourceEntry& e);
    void handleActions(const std::shared_ptr<CActionCollection>& acts);
    void handleFrame(const std::shared_ptr<CSensoryFrame>& sf);
    // A CARMEN output: kept scans as FLASER/RLASER lines, odometry as ODOM lines.
    void handleCarmenEntry(const SourceEntry& e);
    void writeCarmenScan(const CObservation2DRangeScan::Ptr& scan, const Pose2D& odo);
    void writeCarmenOdometry(const Pose2D& odo, double stamp, bool always);
    // Processes one scan through the door; returns true when kept.
    bool handleScan(const CObservation2DRangeScan::Ptr& scan);
    void noteSensor(const CObservation2DRangeScan& scan, const StreamResult& r);
    void noteNoise(const StreamResult& r);
    void write(const mrpt::serialization::CSerializable& obj);
    // Output in input order, through the door (which runs fn at once unless it holds a scan
    // for its next: fn then owns what it writes).
    template <class Fn>
    void emit(Fn&& fn) {
        filter_.then(std::forward<Fn>(fn));
    }
    template <class Ptr>
    void writeShared(const Ptr& obj) {
        emit([this, obj] { write(*obj); });
    }
    void flushUnpairedAction(bool frame_kept);
    void reportProgress(std::uint64_t bytes_read);

    const RawlogFilterOptions& opts_;
    RawlogFilterSummary& sum_;
    StreamFilter filter_;
    std::unique_ptr<Source> source_;
    std::optional<TempOutputFile> tmp_, tmp_csv_;  // the outputs under temporary names
    ScanCsvWriter csv_;
    std::optional<GzOutputStream> gz_;       // a rawlog output
    std::unique_ptr<MessageWriter> bag_;     // a bag output: ROS 1, .db3, .mcap (not gz_)
    std::optional<CarmenWriter> carmen_;     // a CARMEN output (instead of gz_)
    std::optional<Pose2D> carmen_odometry_;  // the odometry of the last line written
    std::vector<CObservation2DRangeScan::Ptr> carmen_unposed_;  // kept before any odometry
    static constexpr std::size_t kCarmenMaxUnposed = 1000;
    std::shared_ptr<CActionCollection> unpaired_action_;  // action waiting for its sensory frame
    CPose2D carry_;  // odometry of dropped frames, not yet written
    bool have_carry_ = false;
    std::optional<Pose2D> odometry_;  // absolute odometry, for the motion guards
    bool saw_frames_ = false, saw_observations_ = false;
    ScanRateMeter rate_;  // the first sensor's stamps (SensorSummary::rate_hz)
};

void Run::write(const mrpt::serialization::CSerializable& obj) {
    try {
        gz_->write(obj);
    } catch (const WriteError& e) {  // "cannot write out.rawlog: No space left on device"
        throw RawlogError(e.what(), opts_.output);
    } catch (const std::exception& e) {
        throw RawlogError(std::string("failed writing the output: ") + e.what());
    }
    ++sum_.objects_out;
}

void Run::noteSensor(const CObservation2DRangeScan& scan, const StreamResult& r) {
    SensorSummary& s = sum_.sensor;
    if (s.beams == 0) {
        const ScanGeometry g{scan.getScanSize(), scan.aperture, scan.rightToLeft};
        s.label = scan.sensorLabel;
        s.beams = g.beams;
        s.aperture_deg = g.aperture * 180.0 / kPi;
        s.resolution_deg = g.resolution() * 180.0 / kPi;
    }
    if (scan.sensorLabel != s.label) return;
    s.odometry = s.odometry || r.record.odometry.has_value();
    rate_.add(r.record.stamp);
}

void Run::noteNoise(const StreamResult& r) {
    SensorSummary& s = sum_.sensor;
    if (r.keep && r.scan && r.scan->sensorLabel == s.label)
        if (const auto* d = r.report.find<DenoiseResult>())
            if (d->variant == DenoiseVariant::Evidence) {
                const auto& ev = opts_.pipeline.get<EvidenceDenoiseStage>();
                s.range_noise_m = d->sigma;
                s.range_noise_measured_m = d->sigma_measured;
                s.range_noise_floor_m = ev.min_sigma_m;
                s.range_noise_configured = ev.sigma_m > 0.0;
            }
}

bool Run::handleScan(const CObservation2DRangeScan::Ptr& ptr) {
    CObservation2DRangeScan& scan = *ptr;
    // Its row once finished (ptr keeps the scan alive while the door holds it).
    return filter_
        .process(scan, odometry_,
                 [this, ptr](StreamResult& done) {
                     if (done.skipped == ScanSkipReason::None) noteSensor(*ptr, done);
                     noteNoise(done);
                     if (csv_.isOpen()) asRawlogError([&] { csv_.write(done.record); });
                 })
        .keep;
}

void Run::handleActions(const std::shared_ptr<CActionCollection>& acts) {
    // Two actions in a row (no frame between): the first stands on its own.
    if (unpaired_action_) flushUnpairedAction(true);
    unpaired_action_ = acts;
}

// Writes the unpaired action (with any carried odometry composed in) or, when its frame was
// dropped, folds its motion into the carry for the next kept action.
void Run::flushUnpairedAction(bool frame_kept) {
    if (!unpaired_action_) return;
    auto acts = unpaired_action_;
    unpaired_action_.reset();
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
    writeShared(acts);
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
        if (handleScan(scan)) {
            ++it;
        } else {
            it = sf->erase(it);
        }
    }
    const bool frame_kept = !(scans > 0 && sf->size() == 0);
    flushUnpairedAction(frame_kept);
    if (frame_kept)
        writeShared(sf);
    else
        ++sum_.objects_dropped;
}

// The paths, the formats and the source; nothing is written yet.
void Run::prepare() {
    std::error_code ec;
    if (!fs::is_regular_file(opts_.input, ec) && !fs::is_directory(opts_.input, ec))
        throw RawlogError("input log not found: " + opts_.input);  // a folder: rosbag2
    if (opts_.output.empty()) throw RawlogError("no output file given");
    // Before anything is opened for writing: no output may be an input or the other output.
    try {
        checkOutputPaths({{"input rawlog", opts_.input}},
                         {{"output rawlog", opts_.output}, {"stats file", opts_.stats_csv}});
    } catch (const PathError& e) {  // reported like every other output problem of this class
        throw RawlogError(e.what(), e.field());
    }
    const std::string& o = opts_.output;
    sum_.output_format = asRawlogError([&] { return outputFormat(o); });
    sum_.input_format = asRawlogError([&] { return detectFormat(opts_.input); });
    if (sum_.output_format == LogFormat::Bag && sum_.input_format != LogFormat::Bag)
        throw RawlogError("a bag output (" + o + ") needs a ROS 1 bag input; " + opts_.input +
                              " is read as: " + toString(sum_.input_format) +
                              (isRos2(sum_.input_format) ? " (write a .db3 or .mcap instead)"
                                                         : " (write a .rawlog instead)"),
                          o);
    if (isRos2(sum_.output_format) && !isBagLike(sum_.input_format))
        throw RawlogError("a ROS 2 output (" + o +
                              ") needs a bag input (ROS 1, rosbag2 or "
                              "MCAP); " +
                              opts_.input + " is read as: " + toString(sum_.input_format) +
                              " (write a .rawlog instead)",
                          o);
    source_ =
        asRawlogError([&] { return openSource(opts_.input, sum_.input_format, opts_.source); });
    if (const auto* bag = dynamic_cast<const BagSource*>(source_.get())) {
        const BagChoice& c = bag->choice();
        sum_.unread_scans = c.unread_scans;
        sum_.layout = "scans " + c.scan_topic + ", odometry " +
                      (c.odometry == BagChoice::Odometry::None ? std::string("none")
                       : c.odometry == BagChoice::Odometry::Tf
                           ? c.odom_topic + " " + c.odom_frame + "->" + c.base_frame
                           : c.odom_topic);
    }
}

// Both outputs are written under temporary names beside them and renamed at the end; on any
// failure or cancellation the destructors remove them.
void Run::openOutputs() {
    asRawlogError([&] { tmp_.emplace(opts_.output); });
    if (sum_.output_format == LogFormat::Bag) {
        BagWriterOptions bag = opts_.bag;  // AsInput: the input bag's compression, else none
        if (bag.compression == BagWriterOptions::Compression::AsInput) {
            const auto* in = dynamic_cast<const BagSource*>(source_.get());
            bag.compression = parseBagCompression(in ? in->compression() : "none");
        }
        sum_.output_compression = toString(bag.compression);
        asRawlogError(
            [&] { bag_ = std::make_unique<BagWriter>(tmp_->path().string(), bag, opts_.output); },
            opts_.output);
    } else if (isRos2(sum_.output_format)) {
        asRawlogError(
            [&] {
                BagWriterOptions bag = opts_.bag;  // AsInput: the input's none/lz4/zstd, or zstd
                if (bag.compression == BagWriterOptions::Compression::AsInput) {
                    const auto* in = dynamic_cast<const BagSource*>(source_.get());
                    const std::string c = in ? in->compression() : "zstd";
                    bag.compression = parseBagCompression(
                        c == "none" || c == "lz4" || c == "zstd" ? c : std::string("zstd"));
                }
                sum_.output_compression =
                    sum_.output_format == LogFormat::Mcap ? toString(bag.compression) : "none";
                bag_ = std::make_unique<Ros2Writer>(tmp_->path().string(), sum_.output_format, bag,
                                                    opts_.output);
            },
            opts_.output);
    } else if (sum_.output_format == LogFormat::Carmen) {
        const bool gzip = hasExtension(opts_.output, ".gz");
        asRawlogError([&] {
            carmen_.emplace(tmp_->path(), opts_.output, gzip, opts_.compress_level,
                            "kept scans of " + opts_.input + " (kfd-filter)");
        });
    } else {
        asRawlogError([&] { gz_.emplace(tmp_->path(), opts_.output, opts_.compress_level); });
    }
    if (!opts_.stats_csv.empty()) {
        asRawlogError([&] {
            tmp_csv_.emplace(opts_.stats_csv);
            csv_.open(tmp_csv_->path().string(), opts_.stats_csv, filter_.outputs());
        });
    }
}

void Run::loop() {
    const std::size_t every = std::max<std::size_t>(1, opts_.progress_every);
    SourceEntry e;
    while (asRawlogError([&] { return source_->next(e); })) {
        throwIfCancelled();
        const std::size_t before = sum_.objects_in;
        sum_.objects_in = e.objects_read;
        e.forEachObject([&](const auto&) { ++sum_.objects_converted; });
        odometry_ = e.odometry;
        handleEntry(e);
        if (before / every != sum_.objects_in / every) reportProgress(source_->bytesRead());
    }
    if (sum_.objects_in == 0) throw RawlogError("no objects in " + opts_.input + ": not a rawlog?");
    // Nothing to filter: an error, not an empty output (nothing is committed).
    const std::string none = noUsableScan(filter_.counters(), source_->counters(), opts_.input);
    if (!none.empty()) throw RawlogError(none, opts_.input);
}

void Run::handleEntry(const SourceEntry& e) {
    if (carmen_) return handleCarmenEntry(e);
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
        case SourceEntry::Kind::Observation:
            saw_observations_ = true;
            flushUnpairedAction(true);
            handleObservation(e);
            break;
        case SourceEntry::Kind::Other:
            flushUnpairedAction(true);
            writeShared(e.other);
            break;
        case SourceEntry::Kind::Native:  // another topic of a bag
            if (bag_)
                emit([this, native = e.native] {
                    asRawlogError([&] { bag_->copy(*native); }, opts_.output);
                    ++sum_.objects_out;
                });
            break;
    }
}

// An observation on its own: a scan goes through the door (kept: written to the rawlog, or
// its original message to the bag with removed points marked); any other observation is copied
// to a rawlog (a bag's own odometry messages are Native entries).
void Run::handleObservation(const SourceEntry& e) {
    auto scan = std::dynamic_pointer_cast<CObservation2DRangeScan>(e.observation);
    if (!scan) {
        if (!bag_) writeShared(e.observation);
    } else if (!handleScan(scan)) {
        ++sum_.objects_dropped;
    } else if (!bag_) {
        writeShared(scan);
    } else if (e.native) {
        emit([this, native = e.native, scan] {
            sum_.points_marked +=
                asRawlogError([&] { return bag_->writeScan(*native, *scan); }, opts_.output);
            ++sum_.objects_out;
        });
    }
}

// A kept scan: its FLASER/RLASER line with the entry's odometry; an odometry reading: an ODOM
// line; a dropped scan: an ODOM line when the odometry moved since the last line. Kept scans
// before the log's first odometry wait for it (a scan and its odometry reading often share a
// stamp, the scan first); a scan whose odometry is not finite gets the last one written.
void Run::handleCarmenEntry(const SourceEntry& e) {
    std::optional<Pose2D> odo = e.odometry;
    if (odo && !finitePose(odo->x, odo->y, odo->phi)) odo.reset();
    if (odo && !carmen_unposed_.empty()) {
        for (const auto& scan : carmen_unposed_) writeCarmenScan(scan, *odo);
        carmen_unposed_.clear();
    }
    auto scanOrOdometry = [&](const mrpt::obs::CObservation::Ptr& obs) {
        if (auto scan = std::dynamic_pointer_cast<CObservation2DRangeScan>(obs)) {
            if (!handleScan(scan)) {
                ++sum_.objects_dropped;
                return false;
            }
            if (odo || carmen_odometry_) {
                writeCarmenScan(scan, odo ? *odo : *carmen_odometry_);
            } else {
                if (carmen_unposed_.size() == kCarmenMaxUnposed)
                    throw RawlogError(
                        "a CARMEN output needs the robot's odometry (a FLASER line holds it): "
                        "the first " +
                            std::to_string(kCarmenMaxUnposed) + " kept scans of " + opts_.input +
                            " have none (a laser-only log): write a .rawlog" +
                            (isBagLike(sum_.input_format) ? " or a bag" : ""),
                        opts_.output);
                carmen_unposed_.push_back(scan);
            }
            return true;
        }
        if (odo && std::dynamic_pointer_cast<mrpt::obs::CObservationOdometry>(obs)) {
            writeCarmenOdometry(*odo, stampOf(*obs), true);
            return true;
        }
        return false;
    };
    bool wrote = false;
    mrpt::obs::CObservation::Ptr first;
    if (e.kind == SourceEntry::Kind::Observation) {
        first = e.observation;
        wrote = scanOrOdometry(e.observation);
    } else if (e.kind == SourceEntry::Kind::Frame) {  // the frame's action is in e.odometry
        for (const auto& obs : *e.frame) {
            if (!first) first = obs;
            wrote = scanOrOdometry(obs) || wrote;
        }
    }  // an action alone: its motion goes out with the next frame; other objects: left out
    if (!wrote && odo && first) writeCarmenOdometry(*odo, stampOf(*first), false);
}

void Run::writeCarmenScan(const CObservation2DRangeScan::Ptr& scan, const Pose2D& odo) {
    emit([this, scan, odo] {
        asRawlogError([&] { carmen_->writeScan(*scan, odo); }, opts_.output);
    });
    carmen_odometry_ = odo;
}

void Run::writeCarmenOdometry(const Pose2D& odo, double stamp, bool always) {
    if (!always && carmen_odometry_ && carmen_odometry_->x == odo.x &&
        carmen_odometry_->y == odo.y && carmen_odometry_->phi == odo.phi)
        return;
    emit([this, odo, stamp] {
        asRawlogError([&] { carmen_->writeOdometry(odo, stamp); }, opts_.output);
    });
    carmen_odometry_ = odo;
}

void Run::finish() {
    filter_.finish();  // the last kept scan, when held for its next, and what waits after it
    if (!carmen_unposed_.empty())
        throw RawlogError("a CARMEN output needs the robot's odometry (a FLASER line holds it): " +
                              opts_.input + " has none (a laser-only log): write a .rawlog" +
                              (isBagLike(sum_.input_format) ? " or a bag" : ""),
                          opts_.output);
    flushUnpairedAction(true);
    if (have_carry_) {  // the last frames were dropped: keep their motion as a final action
        CActionCollection acts;
        CActionRobotMovement2D m;
        m.computeFromOdometry(carry_, CActionRobotMovement2D::TMotionModelOptions());
        acts.insert(m);
        write(acts);
        --sum_.actions_merged;  // that motion was written, not merged away
        have_carry_ = false;
    }
    // Every output complete and checked (the gzip's trailer, the bag's index read back, sizes,
    // fsync) before anything is renamed into place.
    asRawlogError([&] {
        if (bag_) {
            bag_->close();
            if (const auto* r2 = dynamic_cast<const Ros2Writer*>(bag_.get())) {
                sum_.messages_left_out = r2->messagesLeftOut();
                sum_.objects_out -= sum_.messages_left_out;
            }
        } else if (carmen_)
            carmen_->close();
        else
            gz_->close();
        csv_.close();
    });
    throwIfCancelled();
    asRawlogError([&] {
        tmp_->commit();
        if (tmp_csv_) tmp_csv_->commit();
    });

    if (sum_.input_format == LogFormat::Carmen)
        sum_.layout = "FLASER/RLASER/RAWLASER/ROBOTLASER and ODOM lines";
    else if (sum_.input_format == LogFormat::Rawlog)
        sum_.layout = saw_frames_ && saw_observations_ ? "mixed"
                      : saw_frames_                    ? "actions+sensory-frames"
                                                       : "observations";
    if (carmen_) sum_.objects_out = carmen_->linesWritten();
    static_cast<ScanCounters&>(sum_) = filter_.counters();
    sum_.source = source_->counters();
    sum_.sensors = filter_.sensorCount();
    const ScanRate rate = rate_.result();
    sum_.sensor.rate_hz = rate.mean_hz;
    sum_.sensor.median_interval_s = rate.median_interval_s;
}

void Run::reportProgress(std::uint64_t bytes_read) {
    if (!opts_.on_progress) return;
    RawlogProgress p;
    p.bytes_read = bytes_read;
    p.bytes_total = source_->bytesTotal();
    p.objects = sum_.objects_in;
    p.scans_in = filter_.counters().scans_in;
    p.scans_kept = filter_.counters().scans_kept;
    opts_.on_progress(p);
}

}  // namespace

RawlogFilterSummary RawlogFilter::run(const RawlogFilterOptions& opts) {
    RawlogFilterSummary sum;
    Run(opts, sum).execute();
    return sum;
}

}  // namespace kfd
