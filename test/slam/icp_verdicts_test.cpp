// ICP's verdicts read from MRPT's map-builder log (libkfd/src/slam/icp_verdicts.h), on
// hand-made log lines: the only place MRPT says how a correction went.
#include "icp_verdicts.h"

#include <gtest/gtest.h>

namespace {

using kfd::icp_slam::IcpVerdicts;
using kfd::icp_slam::parseIcpLogLine;

TEST(IcpVerdicts, AFitLineIsAnAcceptedCorrectionInPercent) {
    const auto v = parseIcpLogLine("[CMetricMapBuilderICP] Fit:87.5% Pose: (1, 2, 3)");
    ASSERT_TRUE(v);
    EXPECT_DOUBLE_EQ(v->goodness, 0.875);
    EXPECT_FALSE(v->rejected);
}

TEST(IcpVerdicts, ALowQualityLineIsARejectedCorrection) {
    const auto v = parseIcpLogLine("Ignoring ICP of low quality: 31.0");
    ASSERT_TRUE(v);
    EXPECT_DOUBLE_EQ(v->goodness, 0.31);
    EXPECT_TRUE(v->rejected);
}

TEST(IcpVerdicts, OtherLinesAndNumbersThatAreNotFiniteAreNoVerdict) {
    EXPECT_FALSE(parseIcpLogLine("Map updated"));
    EXPECT_FALSE(parseIcpLogLine("Fit:"));
    EXPECT_FALSE(parseIcpLogLine("Fit:nan%"));
    EXPECT_FALSE(parseIcpLogLine("Ignoring ICP of low quality: inf"));
}

TEST(IcpVerdicts, CountsAcceptedRejectedAndGapCheckFailuresApart) {
    kfd::IcpSlamSummary sum;
    IcpVerdicts icp(0.4);
    EXPECT_FALSE(icp.ran());
    icp.onBuilderLog("Fit:90%");
    ASSERT_TRUE(icp.ran());
    EXPECT_EQ(icp.count(sum), IcpVerdicts::Verdict::Accepted);
    icp.clear();
    icp.onBuilderLog("Map updated");  // not a verdict: nothing ran
    EXPECT_FALSE(icp.ran());
    icp.onBuilderLog("Ignoring ICP of low quality: 30");  // under the configuration's 0.4
    EXPECT_EQ(icp.count(sum), IcpVerdicts::Verdict::Rejected);
    icp.onBuilderLog("Ignoring ICP of low quality: 60");  // above it: only the gap check
    EXPECT_EQ(icp.count(sum), IcpVerdicts::Verdict::GapCheckFailed);
    EXPECT_EQ(sum.icp_runs, 3u);
    EXPECT_EQ(sum.icp_rejected, 1u);
    EXPECT_EQ(sum.gap_checks_failed, 1u);
    ASSERT_TRUE(icp.median());
    EXPECT_DOUBLE_EQ(*icp.median(), 0.6);  // of 0.9, 0.3, 0.6
    EXPECT_DOUBLE_EQ(icp.minimum(), 0.4);
}

}  // namespace
