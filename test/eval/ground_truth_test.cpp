// kfd/eval/ground_truth.h: a TUM trajectory and a relations file (both 8 numbers a line) told
// apart by content, on hand-made files and on the formats kfd itself writes.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>

#include "kfd/eval/ground_truth.h"
#include "kfd/eval/trajectory.h"
#include "test_files.h"

namespace {

using kfd::GroundTruthFormat;

struct TempDir : kfd::test::TempDir {
    TempDir() : kfd::test::TempDir("kfd_gtformat_") {}
};

GroundTruthFormat formatOf(const TempDir& d, const std::string& text) {
    const std::string f = d / "gt.txt";
    std::ofstream(f) << text;
    return kfd::detectGroundTruthFormat(f).format;
}

// A planar trajectory along a curve, stamps from t0 every dt (s), as writeTum writes it.
kfd::Trajectory curve(double t0, double dt, int n) {
    kfd::Trajectory t;
    for (int i = 0; i < n; ++i) t.push_back({t0 + dt * i, {0.3 * i, 0.1 * i * i / n, 0.05 * i}});
    return t;
}

}  // namespace

TEST(GroundTruthFormat, RelationsWithEpochStampsAreRelations) {
    TempDir d;  // Kümmerle et al.'s layout: t2 = a later stamp, often another row's t1
    EXPECT_EQ(formatOf(d,
                       "976052905.167303 976052911.885496 -0.05699 -0.12843 0 0 0 -1.68221\n"
                       "976052896.784509 976052905.167303 -0.15313 -0.05142 0 0 0 -2.40585\n"
                       "976052911.885496 976052913.712702 0.33278 -0.00592 0 0 0 -0.01915\n"),
              GroundTruthFormat::Relations);
}

TEST(GroundTruthFormat, RelationsWithAFewBackwardPairsAreStillRelations) {
    TempDir d;  // intel.relations has 6 of 2984 rows with t2 < t1
    std::string text;
    for (int i = 0; i < 20; ++i) {
        const double t1 = 90.0 + i, t2 = i == 7 ? t1 - 0.5 : t1 + 1.0;
        text += std::to_string(t1) + " " + std::to_string(t2) + " 0.42 -0.01 0 0 0 0.02\n";
    }
    EXPECT_EQ(formatOf(d, text), GroundTruthFormat::Relations);
}

TEST(GroundTruthFormat, StraightLineRelationsChainedByStampAreRelations) {
    TempDir d;  // a simulated robot driving straight: y, z, roll, pitch and yaw all 0, so
                // columns 4-6 are zero as in a planar TUM file; the chained stamps decide
    std::string text;
    for (int i = 0; i < 30; ++i)
        text += std::to_string(100.0 + 0.5 * i) + " " + std::to_string(100.5 + 0.5 * i) +
                " 0.376 0 0 0 0 0\n";
    EXPECT_EQ(formatOf(d, text), GroundTruthFormat::Relations);
}

TEST(GroundTruthFormat, TumFilesKfdWritesAreTum) {
    TempDir d;
    for (const double t0 : {0.0, 1.7e9}) {  // a simulation's stamps from 0 and epoch stamps
        const std::string f = d / "traj.tum";
        kfd::writeTum(f, curve(t0, 0.1, 200));
        EXPECT_EQ(kfd::detectGroundTruthFormat(f).format, GroundTruthFormat::Tum) << t0;
    }
}

TEST(GroundTruthFormat, AnUnnormalisedPlanarQuaternionIsTum) {
    TempDir d;  // readTum accepts any non-zero norm (EvalBadInput test): so does the detector
    const double h = 0.3;
    EXPECT_EQ(formatOf(d, "1 0 0 0 0 0 " + std::to_string(5 * std::sin(h)) + " " +
                              std::to_string(5 * std::cos(h)) + "\n"),
              GroundTruthFormat::Tum);
}

TEST(GroundTruthFormat, A3dTumWithUnitQuaternionsIsTum) {
    TempDir d;
    EXPECT_EQ(formatOf(d, "0 1 2 0.5 0.1 0.2 0.3 0.927362\n1 2 3 0.6 0.1 0.2 0.3 0.927362\n"),
              GroundTruthFormat::Tum);
}

TEST(GroundTruthFormat, ContentThatFitsBothOrNeitherIsUnknown) {
    TempDir d;
    // Both: x > t everywhere and yaw 0 (cols 5-7 zero), z qx qy zero; a unit quaternion
    // decides for TUM, without one it stays unknown.
    EXPECT_EQ(formatOf(d, "0 5 0 0 0 0 0 1\n1 6 0 0 0 0 0 1\n"), GroundTruthFormat::Tum);
    EXPECT_EQ(formatOf(d, "0 5 0 0 0 0 0 2\n1 6 0 0 0 0 0 2\n"), GroundTruthFormat::Unknown);
    // Neither: a 3D pose with a quaternion of norm 2 and a second column before the first.
    EXPECT_EQ(formatOf(d, "5 1 2 3 1 1 1 1\n6 1 2 3 1 1 1 1\n"), GroundTruthFormat::Unknown);
    EXPECT_EQ(formatOf(d, "# only a comment\n"), GroundTruthFormat::Unknown);
}

TEST(GroundTruthFormat, TheEvidenceCountsTheRows) {
    TempDir d;
    const std::string f = d / "gt.relations";
    std::ofstream(f)
        << "# t1 t2 x y z roll pitch yaw\n1 2 0.5 0.1 0 0 0 0.1\n2 3 0.5 0.1 0 0 0 0.1\n";
    const auto g = kfd::detectGroundTruthFormat(f);
    EXPECT_EQ(g.format, GroundTruthFormat::Relations);
    EXPECT_EQ(g.rows, 2u);
    EXPECT_EQ(g.later_stamp, 2u);
    EXPECT_EQ(g.shared_stamp, 1u);
    EXPECT_NE(g.evidence().find("2 rows: 2 with a later stamp in column 2"), std::string::npos)
        << g.evidence();
}

TEST(GroundTruthFormat, AMissingFileIsAnEvalError) {
    TempDir d;
    EXPECT_THROW(kfd::detectGroundTruthFormat(d / "missing.tum"), kfd::EvalError);
}
