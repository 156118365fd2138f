// kfd/render/cluster_figure.h: render off-screen, read the pixels back.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <memory>
#include <string>
#include <utility>

#include "kfd/render/cluster_figure.h"
#include "kfd/stages/core_stages.h"
#include "test_scans.h"

namespace {

// A wall at x = +2 m in front of the sensor, |y| <= 1.5 m.
kfd::Scan wallAhead() {
    kfd::Scan s = kfd::test::emptyScan(721, kfd::kPi);
    for (std::size_t i = 0; i < 721; ++i) {
        const double c = std::cos(s.geometry.angle(i));
        if (c < 0.8) continue;
        s.range[i] = static_cast<float>(2.0 / c);
        s.valid[i] = 1;
    }
    return s;
}

// CImage stores 3-channel images as BGR.
std::array<std::uint8_t, 3> rgbAt(const mrpt::img::CImage& img, int x, int y) {
    const auto* p = img.ptr<std::uint8_t>(x, y);
    return {p[2], p[1], p[0]};
}

bool colourNear(const mrpt::img::CImage& img, int cx, int cy, std::array<std::uint8_t, 3> rgb) {
    for (int dy = -2; dy <= 2; ++dy)
        for (int dx = -2; dx <= 2; ++dx)
            if (rgbAt(img, cx + dx, cy + dy) == rgb) return true;
    return false;
}

std::size_t beamAt(const kfd::Scan& s, double angle) {
    std::size_t best = 0;
    for (std::size_t i = 0; i < s.size(); ++i)
        if (std::abs(s.geometry.angle(i) - angle) < std::abs(s.geometry.angle(best) - angle))
            best = i;
    return best;
}

// The clusters kfd's default denoising stage (evidence_denoise) finds in `scan` (denoised).
kfd::Clusters denoised(kfd::Scan& scan) {
    kfd::EvidenceDenoiseStage stage;
    kfd::StageReport report;
    stage.process(scan, report, kfd::ScanReport{});
    return *stage.clusters();
}

}  // namespace

TEST(ClusterFigure, ClusterPointsHaveTheirColourPlusXIsRightAndPlusYIsUp) {
    std::unique_ptr<kfd::ClusterFigure> fig;
    try {
        kfd::ClusterFigureOptions o;
        o.width = o.height = 400;
        o.half_extent_m = 3.0;
        fig = std::make_unique<kfd::ClusterFigure>(o);
    } catch (const kfd::RenderError& e) {
        GTEST_SKIP() << "no off-screen OpenGL here: " << e.what();
    }
    const kfd::Scan s = wallAhead();
    kfd::Scan work = s;  // kfd's default denoiser: the wall is one cluster
    const kfd::Clusters clusters = denoised(work);
    const auto img = fig->render(s, clusters);
    ASSERT_EQ(img.getWidth(), 400u);
    ASSERT_EQ(img.getHeight(), 400u);

    // A wall point on the +y side: (2, 2 tan 0.5) = (2, 1.09) m.
    const std::size_t i = beamAt(s, 0.5);
    ASSERT_TRUE(s.valid[i]);
    const auto label = clusters.label[i];
    ASSERT_GE(label, 0);
    const double x = s.range[i] * std::cos(s.geometry.angle(i));
    const double y = s.range[i] * std::sin(s.geometry.angle(i));
    const auto [px, py] = fig->pixelOf(x, y);
    EXPECT_GT(px, 200);  // +x right of the centre
    EXPECT_LT(py, 200);  // +y above the centre
    EXPECT_TRUE(colourNear(img, px, py, kfd::ClusterFigure::colourOf(label, false)))
        << "no cluster colour near (" << px << ", " << py << ")";
    // The mirrored place (-x, same y) is empty: background or grid, light grey at most.
    const auto [mx, my] = fig->pixelOf(-x, y);
    const auto bg = rgbAt(img, mx, my);
    EXPECT_GE(int(bg[0]) + bg[1] + bg[2], 3 * 200);
    // Not blank: many coloured pixels.
    std::size_t coloured = 0;
    for (unsigned r = 0; r < img.getHeight(); ++r)
        for (unsigned c = 0; c < img.getWidth(); ++c) {
            const auto v = rgbAt(img, int(c), int(r));
            coloured +=
                std::abs(int(v[0]) - int(v[1])) > 40 || std::abs(int(v[2]) - int(v[1])) > 40;
        }
    EXPECT_GT(coloured, 100u);
}

TEST(ClusterFigure, NoisePointsAreRed) {
    std::unique_ptr<kfd::ClusterFigure> fig;
    try {
        kfd::ClusterFigureOptions o;
        o.width = o.height = 300;
        o.half_extent_m = 3.0;
        fig = std::make_unique<kfd::ClusterFigure>(o);
    } catch (const kfd::RenderError& e) {
        GTEST_SKIP() << "no off-screen OpenGL here: " << e.what();
    }
    kfd::Scan s = wallAhead();
    const std::size_t lone = beamAt(s, -1.2);  // an isolated return far from the wall
    s.range[lone] = 1.5f;
    s.valid[lone] = 1;
    kfd::Scan work = s;
    const kfd::Clusters clusters = denoised(work);
    ASSERT_FALSE(work.valid[lone]);  // removed as noise
    const auto img = fig->render(s, clusters);
    const auto [px, py] = fig->pixelOf(1.5 * std::cos(s.geometry.angle(lone)),
                                       1.5 * std::sin(s.geometry.angle(lone)));
    EXPECT_GT(py, 150);  // -y below the centre
    EXPECT_TRUE(colourNear(img, px, py, kfd::ClusterFigure::colourOf(0, true)));
}

TEST(ClusterFigure, SizesOutsideThePixelBudgetAreRefusedBeforeAnyAllocation) {
    for (const auto& [w, h] : {std::pair{8, 800}, std::pair{20000, 100}, std::pair{9000, 9000}}) {
        kfd::ClusterFigureOptions o;
        o.width = w, o.height = h;
        try {  // refused for its size, whether or not OSMesa is there
            kfd::ClusterFigure fig(o);
            ADD_FAILURE() << w << " x " << h << " accepted";
        } catch (const kfd::RenderError& e) {
            EXPECT_NE(std::string(e.what()).find("figure size"), std::string::npos) << e.what();
        }
    }
}
