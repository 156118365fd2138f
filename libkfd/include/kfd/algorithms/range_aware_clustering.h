// Improved clustering variant (beyond the paper): range-aware splitting between nearby beams.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "kfd/paper/clusters.h"
#include "kfd/pipeline/error.h"
#include "kfd/pipeline/scan.h"

namespace kfd {

/// Why: the literal Algorithm 2 splits only at angle gaps inside a ring. With t = 5 and
/// r_max ~ 30 m almost every indoor point lies in ring 1, so a spike in front of a wall joins
/// the wall's cluster, and nothing ever separates objects at different depths.
///
/// This variant walks the beams in scan order and links each valid point to the nearest
/// still-open cluster whose last point is
///  - within theta_threshold in angle (the paper's angle test, Sec. 3.2.2), and
///  - within the jump distance D = min(r_a, r_b) * sin(min(dtheta, lambda/2)) / sin(lambda)
///    + 3 * sigma (a simplified adaptive breakpoint after Borges & Aldon 2004: a surface seen at
///    less than lambda from grazing, or separated in depth, is a different object). The angle
///    is capped at lambda/2 so that a wide gap (theta_threshold is 10 beams, 10 degrees on a
///    1-degree scanner) never lets a point link to something at twice its depth.
/// A point that matches no open cluster starts one; a point that matches several joins them.
/// Because open clusters stay open across a few beams, a one-beam spike in front of a wall
/// becomes its own tiny cluster while the wall on both sides stays one cluster.
/// On a scanner whose field of view closes the circle the same test is applied across the
/// seam. O(beams * open clusters), open clusters <= theta_threshold / resolution + 1.
class RangeAwareClustering {
  public:
    struct Params {
        double angle_gap_factor = 10.0;  // theta_threshold = factor x resolution (Sec. 3.2.2)
        double jump_lambda_deg = 10.0;   // lambda (deg): incidence angle limit of the breakpoint
        double jump_sigma_m = 0.03;      // sigma (m): range noise of the sensor
    };

    struct Result {
        std::size_t links = 0;   // points joined to an open cluster
        std::size_t splits = 0;  // points within theta_threshold of an open cluster but too far
        std::size_t merges = 0;  // clusters joined by a bridging point or across the seam
        double theta_threshold = 0.0;  // rad
    };

    RangeAwareClustering() { initialize(Params{}); }
    explicit RangeAwareClustering(const Params& p) { initialize(p); }
    void initialize(const Params& p);  // kfd::ParameterError on bad values
    const Params& params() const { return params_; }

    Result cluster(const Scan& scan, Clusters& out);

    /// The jump distance D (m) allowed between points at ranges ra, rb, dtheta (rad) apart.
    double jumpDistance(double ra, double rb, double dtheta) const;

  private:
    struct Open {
        std::uint32_t id;
        std::uint32_t beam;
        float x, y, r;
    };

    // jump_factor_ and noise_ for angle gaps up to theta (rad) on beams res_ang apart.
    void updateJumpFactors(double theta, double res_ang);
    // Beam i (valid) joins the nearest open cluster it reaches (uniting the others it reaches)
    // or opens one.
    void addBeam(const Scan& scan, std::size_t i, double theta, double res_ang, Result& res);
    // A scanner closing the circle: clusters open at the end against the first beams.
    void joinAcrossSeam(const Scan& scan, double theta, Result& res);

    Params params_;
    double sin_lambda_ = 0.0;
    double half_lambda_ = 0.0;
    BeamDirections dirs_;
    std::vector<Open> open_;
    std::vector<std::uint8_t> reach_;  // per open cluster: reached by the current point
    std::vector<double> jump_factor_;  // per beam gap: sin(min(gap*res, lambda/2))/sin(lambda)
    double noise_ = 0.0;               // 3 sigma
    DisjointSets sets_;
    std::vector<std::int32_t> provisional_;
};

}  // namespace kfd
