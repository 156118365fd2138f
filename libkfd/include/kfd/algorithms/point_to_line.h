// The normal equations of a 2D projective point-to-line alignment and its damped Gauss-Newton
// step, shared by the evidence denoiser (EvidenceFilter::refineStep) and fused keyframes
// (ScanFusion::refine). std only.
#pragma once

#include <cmath>
#include <cstddef>

#include "kfd/pipeline/scan.h"

namespace kfd {

/// The unit normal (nx, ny) of the line through a = (ax, ay) and b = (bx, by), and the signed
/// distance e of q = (qx, qy) from it: one point-line pair. False when a and b coincide (closer
/// than 1e-6 m).
inline bool pointToLine(float ax, float ay, float bx, float by, float qx, float qy, float& nx,
                        float& ny, float& e) {
    nx = ay - by;
    ny = bx - ax;
    const float len2 = nx * nx + ny * ny;
    if (!(len2 > 1e-12f)) return false;
    const float inv = 1.0f / std::sqrt(len2);
    nx *= inv;
    ny *= inv;
    e = nx * (qx - ax) + ny * (qy - ay);
    return true;
}

/// The upper triangle of J^T J (A) and J^T e (b) over the point-line pairs added, for the
/// increment (dx, dy, dtheta) of a step q' = R(dtheta) q + (dx, dy). T is the accumulator type
/// (float in the denoiser, double in the fusion); each pair's products are formed in float.
template <class T>
struct PointToLineSystem {
    T A[6] = {0, 0, 0, 0, 0, 0};
    T b[3] = {0, 0, 0};
    std::size_t pairs = 0;

    /// A point q = (qx, qy) at signed distance e from a line of unit normal (nx, ny).
    void add(float nx, float ny, float qx, float qy, float e) {
        const float j2 = -nx * qy + ny * qx;  // d e / d theta (rotation about the origin)
        A[0] += nx * nx;
        A[1] += nx * ny;
        A[2] += nx * j2;
        A[3] += ny * ny;
        A[4] += ny * j2;
        A[5] += j2 * j2;
        b[0] += nx * e;
        b[1] += ny * e;
        b[2] += j2 * e;
        ++pairs;
    }

    /// Solves the damped normal equations (a corridor leaves one direction unconstrained:
    /// damping 1e-3 per pair, ten times that on the rotation) and composes the increment onto
    /// `d`. False, `d` unchanged, when the system is singular or the increment not finite.
    bool step(Pose2D& d) const {
        const double damp = 1e-3 * static_cast<double>(pairs);
        const double a00 = A[0] + damp, a01 = A[1], a02 = A[2], a11 = A[3] + damp, a12 = A[4],
                     a22 = A[5] + damp * 10.0;
        const double det = a00 * (a11 * a22 - a12 * a12) - a01 * (a01 * a22 - a12 * a02) +
                           a02 * (a01 * a12 - a11 * a02);
        if (!(std::abs(det) > 1e-12)) return false;
        const double b0 = b[0], b1 = b[1], b2 = b[2];
        const double dx = -(b0 * (a11 * a22 - a12 * a12) - a01 * (b1 * a22 - a12 * b2) +
                            a02 * (b1 * a12 - a11 * b2)) /
                          det;
        const double dy = -(a00 * (b1 * a22 - a12 * b2) - b0 * (a01 * a22 - a12 * a02) +
                            a02 * (a01 * b2 - b1 * a02)) /
                          det;
        const double dt = -(a00 * (a11 * b2 - b1 * a12) - a01 * (a01 * b2 - b1 * a02) +
                            b0 * (a01 * a12 - a11 * a02)) /
                          det;
        if (!std::isfinite(dx) || !std::isfinite(dy) || !std::isfinite(dt)) return false;
        // q' = R(dt) q + (dx, dy): compose the increment onto the step.
        const double cd = std::cos(dt), sd = std::sin(dt);
        d = Pose2D{cd * d.x - sd * d.y + dx, sd * d.x + cd * d.y + dy, d.phi + dt};
        return true;
    }
};

}  // namespace kfd
