// SPDX-License-Identifier: MIT
// Pairwise overlap tests: SAT for boxes, closest points for everything round (Ericson, Real-Time
// Collision Detection, ch. 4-5; Gottschalk, Lin & Manocha 1996).
#include "hbvh/geometry/overlap.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace hbvh {
namespace {

// Rounding relative to the coordinates. A rigid motion x -> R x + T rounds each coordinate at a few u
// times |x| + |T| (u = 2^-53), so two volumes that touch, moved kilometres from the origin, arrive apart (or
// apart by an ulp, overlapping) by ~10 u x |coordinates| whatever their size; computing t = b.center -
// a.center rounds at u x |coordinates| again. Every test below therefore accepts separations up to a slack
// proportional to the magnitude of the coordinates involved (L1 norms, cheap and >= the Euclidean ones),
// not only to the volumes' sizes: touching counts anywhere in the world, and the extra pairs it reports
// are within the documented band (docs/reliability.md, "Precision").

// Box-box SAT, all 15 axes. Edge-edge axes L = A_i x B_j vanish when the edges are parallel; then both
// sides of the test are rounding noise of order u * |t|. A slack of 1e-13 (about 450 u) of the
// configuration's size and coordinates keeps such a degenerate axis from separating overlapping boxes
// (Ericson 4.4.1 adds an epsilon to |R| for the same reason; an absolute slack keeps the test scale-free),
// and covers the coordinate rounding above on the face axes. On a genuine axis the slack is negligible.
constexpr double box_axis_slack = 1e-13;

// boxes_may_overlap() must never separate boxes that overlaps() accepts, though it computes R and t in a
// different order (b's axes moved into a's frame by one more product, the centre through another chain of
// sums): 1e-12, ten times box_axis_slack on at least the same terms, covers that rounding (a few u times
// size and coordinates) with a wide margin and is still far below any real gap.
constexpr double face_axis_slack = 1e-12;

// Round tests (and Aabb-Aabb) accept separations up to 1e-14 (about 45 u) of the coordinate magnitude plus
// the reach: enough for the ~10-20 u a rigid motion (or pose composition) rounds, and the distance kernels'
// own rounding relative to the reach; tight enough to keep extra pairs within ~1e-13 x |coordinates|.
constexpr double round_slack = 1e-14;

// Segment pairs with sin^2(angle) below this are "nearly parallel": the line-line solution loses
// accuracy as u / sin(angle), so endpoint distances (exact for parallel segments) join the candidates.
constexpr double parallel_sin2 = 1e-6;

/// L1 norm: the coordinate magnitude the slacks are proportional to.
inline double magnitude(const Vec3& v) { return v.cwiseAbs().sum(); }

/// True when a squared distance is at most (reach + slack)^2: the round tests' comparison, conservative by
/// round_slack of the coordinate magnitude `coordinates` and of the reach itself.
inline bool within_reach(double squared_distance, double reach, double coordinates) {
    const double r = reach + round_slack * (coordinates + reach);
    return squared_distance <= r * r;
}

/// SAT core. B's axes in A's frame are R's columns (R(i, j) = A_i . B_j), t = B's centre in A's frame;
/// `coordinates` is the magnitude of the coordinates t was computed from (|a.center| + |b.center|).
bool boxes_overlap(const Vec3& ea, const Vec3& eb, const Mat3& R, const Vec3& t, double coordinates) {
    const Mat3 abs_r = R.cwiseAbs();
    const double slack = box_axis_slack * (magnitude(t) + ea.sum() + eb.sum() + coordinates);
    // Stage 1: A's three face normals.
    for (int i = 0; i < 3; ++i)
        if (std::abs(t[i]) > ea[i] + eb.dot(abs_r.row(i)) + slack) return false;
    // Stage 2: B's three face normals.
    for (int j = 0; j < 3; ++j)
        if (std::abs(t.dot(R.col(j))) > eb[j] + ea.dot(abs_r.col(j)) + slack) return false;
    // Stage 3: the nine edge-edge axes A_i x B_j, written out with the identities of orthonormal frames
    // so that no axis is formed explicitly (Gottschalk 1996; Ericson 4.4.1).
    for (int i = 0; i < 3; ++i) {
        const int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
        for (int j = 0; j < 3; ++j) {
            const int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
            const double ra = ea[i1] * abs_r(i2, j) + ea[i2] * abs_r(i1, j);
            const double rb = eb[j1] * abs_r(i, j2) + eb[j2] * abs_r(i, j1);
            if (std::abs(t[i2] * R(i1, j) - t[i1] * R(i2, j)) > ra + rb + slack) return false;
        }
    }
    return true;
}

/// Signed amount by which x lies outside [-h, h] (0 inside).
inline double excess(double x, double h) { return x > h ? x - h : (x < -h ? x + h : 0.0); }

double point_box_squared_distance(const Vec3& p, const Vec3& h) {
    const double x = excess(p.x(), h.x()), y = excess(p.y(), h.y()), z = excess(p.z(), h.z());
    return x * x + y * y + z * z;
}

double point_segment_squared_distance(const Vec3& point, const Vec3& p0, const Vec3& p1) {
    const Vec3 d = p1 - p0;
    const double dd = d.squaredNorm();
    const Vec3 w = point - p0;
    if (dd <= 0.0) return w.squaredNorm();
    const double t = std::clamp(w.dot(d) / dd, 0.0, 1.0);
    return (w - t * d).squaredNorm();
}

/// Half the derivative of the squared point-box distance along p + t d: sum_i d_i * excess_i.
inline double box_distance_slope(const Vec3& p, const Vec3& d, const Vec3& h, double t) {
    return d.x() * excess(p.x() + t * d.x(), h.x()) + d.y() * excess(p.y() + t * d.y(), h.y()) +
           d.z() * excess(p.z() + t * d.z(), h.z());
}

/// Capsule vs box with the capsule already in box coordinates; `coordinates` as in within_reach (the
/// world coordinates the local ones were computed from).
bool capsule_box_local(const Vec3& p0, const Vec3& p1, double radius, const Vec3& h, double coordinates) {
    const double slack = round_slack * (coordinates + h.sum() + radius);
    // Cheap rejection: both ends beyond the same slab face by more than the radius (and the slack).
    for (int i = 0; i < 3; ++i) {
        const double reach = h[i] + radius + slack;
        if ((p0[i] > reach && p1[i] > reach) || (p0[i] < -reach && p1[i] < -reach)) return false;
    }
    return within_reach(segment_box_squared_distance(p0, p1, h), radius, coordinates + h.sum());
}

}  // namespace

double segment_box_squared_distance(const Vec3& p0, const Vec3& p1, const Vec3& h) {
    // f(t) = dist^2(p0 + t d, box) is convex and C^1 with a piecewise-linear, non-decreasing derivative
    // whose kinks are where a coordinate crosses a slab face. The minimiser on [0, 1] is an end whose
    // slope points inwards, or the zero of the slope inside the bracket of consecutive kinks where its
    // sign changes; on that bracket the slope is linear, so one interpolation finds the zero exactly.
    const Vec3 d = p1 - p0;
    const double g0 = box_distance_slope(p0, d, h, 0.0);
    if (g0 >= 0.0) return point_box_squared_distance(p0, h);
    const double g1 = box_distance_slope(p0, d, h, 1.0);
    if (g1 <= 0.0) return point_box_squared_distance(p1, h);
    // Stage 1: kinks strictly inside (0, 1), sorted (at most 6: insertion sort).
    std::array<double, 6> kinks{};
    int kink_count = 0;
    for (int i = 0; i < 3; ++i) {
        if (d[i] == 0.0) continue;
        for (const double face : {-h[i], h[i]}) {
            const double t = (face - p0[i]) / d[i];
            if (t > 0.0 && t < 1.0) {
                int k = kink_count++;
                while (k > 0 && kinks[k - 1] > t) {
                    kinks[k] = kinks[k - 1];
                    --k;
                }
                kinks[k] = t;
            }
        }
    }
    // Stage 2: bracket the sign change of the slope.
    double lo = 0.0, g_lo = g0, hi = 1.0, g_hi = g1;
    for (int k = 0; k < kink_count; ++k) {
        const double g = box_distance_slope(p0, d, h, kinks[k]);
        if (g >= 0.0) {
            hi = kinks[k];
            g_hi = g;
            break;
        }
        lo = kinks[k];
        g_lo = g;
    }
    // Stage 3: the slope's zero by linear interpolation (g_lo < 0 <= g_hi, so no division by zero).
    const double t = std::clamp(lo + (hi - lo) * (-g_lo / (g_hi - g_lo)), lo, hi);
    return point_box_squared_distance(p0 + t * d, h);
}

double segment_segment_squared_distance(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1) {
    // Ericson 5.1.9: minimise |p0 + s d1 - q0 - t d2|^2 over the unit square by clamping s, solving t,
    // and re-clamping s only when t was clamped.
    const Vec3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
    const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
    if (a <= 0.0 && e <= 0.0) return r.squaredNorm();
    if (a <= 0.0) return point_segment_squared_distance(p0, q0, q1);
    const double c = d1.dot(r);
    if (e <= 0.0) return point_segment_squared_distance(q0, p0, p1);
    const double b = d1.dot(d2);
    const double denom = a * e - b * b;  // |d1|^2 |d2|^2 sin^2(angle) >= 0
    double s = denom > 0.0 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
    double t = (b * s + f) / e;
    if (t < 0.0) {
        t = 0.0;
        s = std::clamp(-c / a, 0.0, 1.0);
    } else if (t > 1.0) {
        t = 1.0;
        s = std::clamp((b - c) / a, 0.0, 1.0);
    }
    double best = (r + s * d1 - t * d2).squaredNorm();
    if (denom <= parallel_sin2 * a * e) {
        // Nearly parallel: some endpoint is always in a closest pair of parallel segments, so the
        // endpoint distances are exact where the line solution is ill-conditioned.
        best = std::min({best, point_segment_squared_distance(p0, q0, q1), point_segment_squared_distance(p1, q0, q1),
                         point_segment_squared_distance(q0, p0, p1), point_segment_squared_distance(q1, p0, p1)});
    }
    return best;
}

bool boxes_may_overlap(const Vec3& ea, const Vec3& eb, const Mat3& r, const Vec3& t, double coordinates) {
    const Mat3 abs_r = r.cwiseAbs();
    const double slack = face_axis_slack * (magnitude(t) + ea.sum() + eb.sum() + coordinates);
    for (int i = 0; i < 3; ++i)
        if (std::abs(t[i]) > ea[i] + eb.dot(abs_r.row(i)) + slack) return false;
    for (int j = 0; j < 3; ++j)
        if (std::abs(t.dot(r.col(j))) > eb[j] + ea.dot(abs_r.col(j)) + slack) return false;
    return true;
}

bool overlaps(const Aabb& a, const Aabb& b) {
    // The comparisons themselves are exact; the slack is for the rounding that placed the boxes.
    const double slack =
        round_slack * (magnitude(a.min) + magnitude(a.max) + magnitude(b.min) + magnitude(b.max));
    return (a.min.array() <= b.max.array() + slack).all() && (b.min.array() <= a.max.array() + slack).all();
}

bool overlaps(const Aabb& a, const Obb& b) {
    // The Aabb is an Obb with identity axes, so R is b's rotation and t stays in world axes.
    const Vec3 c = a.center();
    return boxes_overlap(a.half_extents(), b.half_extents, b.rotation, b.center - c,
                         magnitude(c) + magnitude(b.center));
}

bool overlaps(const Aabb& a, const Sphere& b) {
    // Ericson 5.2.5: the closest point of the box is the clamped centre.
    const Vec3 closest = b.center.cwiseMax(a.min).cwiseMin(a.max);
    return within_reach((closest - b.center).squaredNorm(), b.radius, magnitude(b.center) + magnitude(closest));
}

bool overlaps(const Aabb& a, const Capsule& b) {
    const Vec3 c = a.center();
    return capsule_box_local(b.p0 - c, b.p1 - c, b.radius, a.half_extents(),
                             magnitude(c) + magnitude(b.p0) + magnitude(b.p1));
}

bool overlaps(const Obb& a, const Obb& b) {
    const Mat3 rt = a.rotation.transpose();
    return boxes_overlap(a.half_extents, b.half_extents, rt * b.rotation, rt * (b.center - a.center),
                         magnitude(a.center) + magnitude(b.center));
}

bool overlaps(const Obb& a, const Sphere& b) {
    const Vec3 local = a.rotation.transpose() * (b.center - a.center);
    return within_reach(point_box_squared_distance(local, a.half_extents), b.radius,
                        magnitude(a.center) + magnitude(b.center) + a.half_extents.sum());
}

bool overlaps(const Obb& a, const Capsule& b) {
    const Mat3 rt = a.rotation.transpose();
    return capsule_box_local(rt * (b.p0 - a.center), rt * (b.p1 - a.center), b.radius, a.half_extents,
                             magnitude(a.center) + magnitude(b.p0) + magnitude(b.p1));
}

bool overlaps(const Sphere& a, const Sphere& b) {
    return within_reach((a.center - b.center).squaredNorm(), a.radius + b.radius,
                        magnitude(a.center) + magnitude(b.center));
}

bool overlaps(const Sphere& a, const Capsule& b) {
    return within_reach(point_segment_squared_distance(a.center, b.p0, b.p1), a.radius + b.radius,
                        magnitude(a.center) + magnitude(b.p0) + magnitude(b.p1));
}

bool overlaps(const Capsule& a, const Capsule& b) {
    return within_reach(segment_segment_squared_distance(a.p0, a.p1, b.p0, b.p1), a.radius + b.radius,
                        magnitude(a.p0) + magnitude(a.p1) + magnitude(b.p0) + magnitude(b.p1));
}

bool overlaps(const BoundingVolume& a, const BoundingVolume& b) {
    return std::visit([](const auto& x, const auto& y) { return overlaps(x, y); }, a, b);
}

}  // namespace hbvh
