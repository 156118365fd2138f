#include "kfd/stages/fuse_stage.h"

#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "kfd/pipeline/pipeline.h"
#include "kfd/pipeline/stage_registry.h"
#include "test_scans.h"

namespace kfd {
namespace {

// Drops every scan but every `period`-th (a stand-in for the keyframe stage).
class EveryNth : public Stage {
  public:
    explicit EveryNth(int period) : period_(period) {}
    const char* name() const override { return "every_nth"; }
    bool process(Scan&, StageReport&, const ScanReport&) override {
        return ++count_ % period_ == 0;
    }

  private:
    int period_;
    int count_ = 0;
};

// A wall 3 m ahead, 181 beams over 180 degrees, range noise 2 cm.
Scan noisyFlatWall(std::mt19937& rng) {
    Scan s = test::flatWall(181, kPi, 3.0);
    std::normal_distribution<float> noise(0.0f, 0.02f);
    for (auto& r : s.range) r += noise(rng);
    s.odometry = Pose2D{};
    return s;
}

double rmsToWall(const Scan& s) {
    const Scan truth = test::flatWall(181, kPi, 3.0);
    double sum = 0.0;
    std::size_t n = 0;
    for (std::size_t i = 0; i < s.size(); ++i)
        if (s.valid[i] && truth.valid[i]) {
            sum += std::pow(s.range[i] - truth.range[i], 2);
            ++n;
        }
    return std::sqrt(sum / static_cast<double>(n));
}

TEST(FuseStage, FusesTheScansAnEarlierStageDroppedIntoTheNextKeptOne) {
    Pipeline::Params params;
    params.stages = {};
    Pipeline p(params);
    p.add(std::make_unique<EveryNth>(5));
    p.add(std::make_unique<FuseStage>());
    std::mt19937 rng(1);
    double before = 0.0, after = 0.0;
    int keyframes = 0;
    for (int k = 0; k < 20; ++k) {
        Scan s = noisyFlatWall(rng);
        const double raw = rmsToWall(s);
        const auto r = p.process(s);
        if (!r.keep) continue;
        const auto* d = r.find<ScanFusion::Result>();
        ASSERT_NE(d, nullptr);
        EXPECT_EQ(d->scans_kept, 4u);
        EXPECT_GT(d->beams_fused, 0u);
        EXPECT_EQ(r.points_in, r.points_out);  // fusion never removes a point
        before += raw;
        after += rmsToWall(s);
        ++keyframes;
    }
    EXPECT_EQ(keyframes, 4);
    EXPECT_LT(after, 0.75 * before);
}

TEST(FuseStage, IsRegisteredWithItsKeys) {
    const StageInfo* info = coreStageRegistry().find("fuse");
    ASSERT_NE(info, nullptr);
    std::vector<std::string> names;
    for (const auto& k : info->keys) names.push_back(k.name);
    EXPECT_EQ(names, (std::vector<std::string>{
                         "fuse_max_scans", "fuse_min_agreeing", "fuse_gate_sigmas",
                         "fuse_max_bias_sigmas", "fuse_estimator", "fuse_min_sigma_m",
                         "fuse_max_step_m", "fuse_max_step_deg", "fuse_max_span_beams",
                         "fuse_refine_iterations", "fuse_refine_samples", "fuse_refine_gate_m"}));
    auto params = info->defaults();
    for (const auto& k : info->keys) {  // every default prints and reads back
        const std::string text = k.get(params->data());
        EXPECT_NO_THROW(k.set(params->data(), text)) << k.name;
        EXPECT_EQ(k.get(params->data()), text) << k.name;
    }
    const StageKey* est = info->keyForField("estimator");
    ASSERT_NE(est, nullptr);
    est->set(params->data(), "mean");
    EXPECT_EQ(est->get(params->data()), "mean");
    EXPECT_THROW(est->set(params->data(), "mode"), ParameterError);
    EXPECT_THROW(info->keyForField("max_scans")->set(params->data(), "0"), ParameterError);
    EXPECT_THROW(info->keyForField("gate_sigmas")->set(params->data(), "-1"), ParameterError);
    // A stage check across keys: more agreeing returns than scans kept.
    info->keyForField("min_agreeing")->set(params->data(), "9");
    info->keyForField("max_scans")->set(params->data(), "8");
    EXPECT_THROW(info->validate(*params), ParameterError);
}

TEST(FuseStage, APipelineNamesItAfterKeyframe) {
    Pipeline::Params params;
    params.stages = {"odometry_check", "distance", "keyframe", "fuse", "denoise"};
    const Pipeline p(params);
    ASSERT_EQ(p.stages().size(), 5u);
    EXPECT_STREQ(p.stages()[3]->name(), "fuse");
}

}  // namespace
}  // namespace kfd
