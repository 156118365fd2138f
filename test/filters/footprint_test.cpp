// The footprint stage (laser_filters' box and polygon filters) on hand-made scans, and its
// point-in-polygon test against a plain reference over random points.
#include "kfd/filters/footprint.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "test_scans.h"

namespace kfd {
namespace {

Footprint box(double min_x, double max_x, double min_y, double max_y) {
    Footprint::Params p;
    p.min_x = min_x;
    p.max_x = max_x;
    p.min_y = min_y;
    p.max_y = max_y;
    return Footprint(p);
}

TEST(Footprint, ReturnsOnTheRobotsBodyAreRemovedAndTheRoomKept) {
    // A room at 3 m; beams 80..100 (-10 .. 10 deg) hit a bumper 0.3 m ahead of the sensor.
    Scan s = test::arc(181, kPi, 3.0);
    test::setRange(s, 80, 100, 0.3);
    const auto r = box(-0.4, 0.4, -0.3, 0.3).filter(s);
    EXPECT_EQ(r.points_removed, 21u);
    for (std::size_t i = 80; i <= 100; ++i) EXPECT_EQ(s.valid[i], 0) << i;
    EXPECT_EQ(s.valid[79], 1);
    EXPECT_EQ(s.valid[101], 1);
}

TEST(Footprint, TheBoxIsInTheRobotsFrameNotTheSensors) {
    // The sensor sits 0.5 m ahead of the robot's centre: a return 0.3 m ahead of the sensor is
    // at x = 0.8 m on the robot, outside a box that ends at 0.6 m.
    Scan s = test::arc(181, kPi, 3.0);
    test::setRange(s, 90, 90, 0.3);
    s.sensor_pose = Pose2D{0.5, 0.0, 0.0};
    EXPECT_EQ(box(-0.4, 0.6, -0.3, 0.3).filter(s).points_removed, 0u);
    s.sensor_pose = Pose2D{0.2, 0.0, 0.0};  // now at x = 0.5 m: inside
    EXPECT_EQ(box(-0.4, 0.6, -0.3, 0.3).filter(s).points_removed, 1u);
}

TEST(Footprint, APolygonRemovesOnlyWhatIsInsideIt) {
    // A triangle ahead of the sensor covering the forward beams at 0.5 m.
    Footprint::Params p;
    p.polygon = Footprint::parsePolygon("polygon", "[[0.1, -0.3], [0.8, 0.0], [0.1, 0.3]]");
    Scan s = test::arc(181, kPi, 0.5);
    const auto r = Footprint(p).filter(s);
    EXPECT_GT(r.points_removed, 0u);
    EXPECT_EQ(s.valid[90], 0);  // straight ahead at 0.5 m: inside
    EXPECT_EQ(s.valid[0], 1);   // to the right at 0.5 m: outside
    EXPECT_EQ(s.valid[180], 1);
}

TEST(Footprint, NoBoxAndNoPolygonRemovesNothing) {
    Scan s = test::arc(181, kPi, 0.1);
    EXPECT_EQ(Footprint().filter(s).points_removed, 0u);
}

TEST(Footprint, PolygonTextParsesAndPrintsBack) {
    const auto v = Footprint::parsePolygon("polygon", "0.1,-0.3; 0.8,0; 0.1,0.3");
    ASSERT_EQ(v.size(), 3u);
    EXPECT_EQ(Footprint::formatPolygon(v), "[[0.1, -0.3], [0.8, 0], [0.1, 0.3]]");
    EXPECT_TRUE(Footprint::parsePolygon("polygon", "[]").empty());
    EXPECT_THROW(Footprint::parsePolygon("polygon", "[[0.1, x]]"), ParameterError);
    EXPECT_THROW(Footprint::parsePolygon("polygon", "[[0.1, 0.2], [0.3]]"), ParameterError);
}

TEST(Footprint, BadShapesAreParameterErrors) {
    EXPECT_THROW(box(0.4, -0.4, -0.3, 0.3), ParameterError);
    Footprint::Params p;
    p.polygon = {{0, 0}, {1, 0}};
    EXPECT_THROW(Footprint{p}, ParameterError);
    p.polygon = {{0, 0}, {1, 0}, {0, NAN}};
    EXPECT_THROW(Footprint{p}, ParameterError);
}

// The even-odd rule written plainly: the winding of the polygon around the point, by angles.
bool plainInside(const std::vector<Footprint::Vertex>& poly, double x, double y) {
    double winding = 0.0;
    for (std::size_t i = 0; i < poly.size(); ++i) {
        const auto& a = poly[i];
        const auto& b = poly[(i + 1) % poly.size()];
        double d = std::atan2(b.y - y, b.x - x) - std::atan2(a.y - y, a.x - x);
        while (d > kPi) d -= 2 * kPi;
        while (d < -kPi) d += 2 * kPi;
        winding += d;
    }
    return std::lround(winding / (2 * kPi)) % 2 != 0;
}

TEST(Footprint, InsideEqualsAPlainWindingTestOnRandomPolygonsAndPoints) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int t = 0; t < 200; ++t) {
        Footprint::Params p;  // a star-shaped polygon (no self-crossing) around the origin
        const int n = 3 + t % 6;
        for (int k = 0; k < n; ++k) {
            const double a = 2 * kPi * k / n, r = 0.3 + 0.6 * (u(rng) + 1) / 2;
            p.polygon.push_back({r * std::cos(a), r * std::sin(a)});
        }
        const Footprint f(p);
        for (int q = 0; q < 50; ++q) {
            const double x = u(rng), y = u(rng);
            EXPECT_EQ(f.inside(x, y), plainInside(p.polygon, x, y)) << t << " " << x << " " << y;
        }
    }
}

}  // namespace
}  // namespace kfd
