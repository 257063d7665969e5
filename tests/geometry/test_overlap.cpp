// SPDX-License-Identifier: MIT
// Overlap tests against independent oracles: libccd (MPR) on support functions, dense brute force for the
// distance kernels, and hand-made touching / separated / nested cases for every pair.
#include <gtest/gtest.h>

#include <ccd/ccd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <numbers>
#include <string>
#include <vector>

#include "hbvh/geometry/overlap.hpp"
#include "hbvh/scene/generate.hpp"

namespace hbvh {
namespace {

// The libccd oracle.
// libccd 2.0 has no GJK distance for disjoint bodies, and its ccdGJKIntersect proved self-inconsistent near
// contact (with 1e-6 relative penetration it answered "disjoint" for bodies whose shrunk copies it called
// "intersecting": hundreds per 100 000 configurations). Its MPR test (Snethen's XenoCollide) on the same
// support functions was consistent in every run, so MPR is the oracle and GJK is not used.

/// A BV for libccd, scaled by `scale` about its centre and grown by a ball of radius `margin`.
/// Scaling about the centre keeps a convex, centrally symmetric body nested: scale < 1 gives a subset,
/// scale > 1 a superset, which is what brackets the oracle's answer.
struct OracleShape {
    BoundingVolume volume;
    double scale = 1.0;
    double margin = 0.0;
    /// Output zoom: libccd's tolerances are absolute, so the oracle works at unit size.
    double unit = 1.0;
    /// Subtracted from every point before the zoom: configurations far from the origin are judged near it.
    /// (x + o) - o is exact when |x| << |o|, so the oracle sees the very geometry the test gave overlaps().
    Vec3 origin = Vec3::Zero();
};

Vec3 center_of(const BoundingVolume& bv) {
    return std::visit(
        [](const auto& v) -> Vec3 {
            using T = std::decay_t<decltype(v)>;
            if constexpr (std::is_same_v<T, Aabb>) return v.center();
            else if constexpr (std::is_same_v<T, Capsule>) return v.center();
            else return v.center;
        },
        bv);
}

Vec3 support_in_model(const OracleShape& shape, const Vec3& dir, const Vec3& unit, const Vec3& c) {
    const auto box_support = [&](const Mat3& axes, const Vec3& half) {
        Vec3 offset = Vec3::Zero();
        for (int k = 0; k < 3; ++k) offset += (axes.col(k).dot(dir) >= 0.0 ? half[k] : -half[k]) * axes.col(k);
        return Vec3(c + shape.scale * offset + shape.margin * unit);
    };
    return std::visit(
        [&](const auto& v) -> Vec3 {
            using T = std::decay_t<decltype(v)>;
            if constexpr (std::is_same_v<T, Aabb>) return box_support(Mat3::Identity(), v.half_extents());
            else if constexpr (std::is_same_v<T, Obb>) return box_support(v.rotation, v.half_extents);
            else if constexpr (std::is_same_v<T, Sphere>) return c + (shape.scale * v.radius + shape.margin) * unit;
            else {
                const Vec3 end = (v.p1 - v.p0).dot(dir) >= 0.0 ? v.p1 : v.p0;
                return c + shape.scale * (end - v.center()) + (shape.scale * v.radius + shape.margin) * unit;
            }
        },
        shape.volume);
}

Vec3 support_of(const OracleShape& shape, const Vec3& dir) {
    const double n = dir.norm();
    const Vec3 unit = n > 0.0 ? Vec3(dir / n) : Vec3::UnitX();
    return shape.unit * support_in_model(shape, dir, unit, center_of(shape.volume) - shape.origin);
}

void ccd_support(const void* object, const ccd_vec3_t* dir, ccd_vec3_t* out) {
    const Vec3 s = support_of(*static_cast<const OracleShape*>(object), Vec3(dir->v[0], dir->v[1], dir->v[2]));
    out->v[0] = s.x();
    out->v[1] = s.y();
    out->v[2] = s.z();
}

void ccd_center(const void* object, ccd_vec3_t* out) {
    const auto* shape = static_cast<const OracleShape*>(object);
    const Vec3 c = shape->unit * (center_of(shape->volume) - shape->origin);
    out->v[0] = c.x();
    out->v[1] = c.y();
    out->v[2] = c.z();
}

bool ccd_intersect(const OracleShape& a, const OracleShape& b) {
    ccd_t ccd;
    CCD_INIT(&ccd);
    ccd.support1 = ccd_support;
    ccd.support2 = ccd_support;
    ccd.center1 = ccd_center;
    ccd.center2 = ccd_center;
    ccd.max_iterations = 1000;
    ccd.mpr_tolerance = 1e-12;
    return ccdMPRIntersect(&a, &b, &ccd) != 0;
}

enum class Verdict { disjoint, overlapping, ambiguous, inconsistent };

/// Relative half-width of the band in which the oracle declines to answer.
constexpr double oracle_band = 1e-8;

/// Absolute half-width added to the band per unit of coordinate magnitude (|origin|_1): overlaps() may
/// accept gaps up to ~1e-13 of the L1 coordinates (docs/reliability.md, "Precision"), so those are
/// declined too, and anything beyond is a disagreement.
constexpr double coordinate_band = 1e-12;

/// MPR on both bodies shrunk by (1 - band) gives "surely overlapping"; on both grown by (1 + band) plus a
/// ball of band * size + coordinate_band * |origin| (so that flat boxes and points grow too) gives "surely
/// disjoint". Anything in between is within ~band of touching and is skipped. `origin` is where the
/// configuration sits (it is judged relative to it).
Verdict oracle(const BoundingVolume& a, const BoundingVolume& b, const Vec3& origin = Vec3::Zero()) {
    const double size = std::max(size_scale(a), size_scale(b));
    const double unit = 1.0 / size;
    const double margin = oracle_band * size + coordinate_band * origin.cwiseAbs().sum();
    const bool grown = ccd_intersect({a, 1.0 + oracle_band, margin, unit, origin}, {b, 1.0 + oracle_band, margin, unit, origin});
    const bool shrunk =
        ccd_intersect({a, 1.0 - oracle_band, 0.0, unit, origin}, {b, 1.0 - oracle_band, 0.0, unit, origin});
    if (shrunk && !grown) return Verdict::inconsistent;
    if (!grown) return Verdict::disjoint;
    return shrunk ? Verdict::overlapping : Verdict::ambiguous;
}

// Random configurations.

double log_uniform(SplitMix64& rng, double lo, double hi) { return lo * std::pow(hi / lo, rng.uniform()); }

/// A random BV of `type` centred at `center`; occasionally degenerate (flat box, zero-length capsule).
BoundingVolume random_volume(SplitMix64& rng, BvType type, const Vec3& center, double size) {
    const auto extent = [&] { return rng.uniform() < 0.03 ? 0.0 : size * log_uniform(rng, 0.05, 1.0); };
    switch (type) {
        case BvType::aabb: {
            const Vec3 h(extent(), extent(), extent());
            return Aabb{center - h, center + h};
        }
        case BvType::obb: return Obb{center, rng.rotation(), Vec3(extent(), extent(), extent())};
        case BvType::sphere: return Sphere{center, size * log_uniform(rng, 0.05, 1.0)};
        case BvType::capsule: {
            const Vec3 axis = rng.rotation().col(0) * extent();
            return Capsule{center - axis, center + axis, size * log_uniform(rng, 0.02, 0.6)};
        }
    }
    return Sphere{center, size};
}

/// The BV scaled by `s` about its centre.
BoundingVolume scaled(const BoundingVolume& bv, double s) {
    return std::visit(
        [&](const auto& v) -> BoundingVolume {
            using T = std::decay_t<decltype(v)>;
            if constexpr (std::is_same_v<T, Aabb>) {
                const Vec3 c = v.center(), h = s * v.half_extents();
                return Aabb{c - h, c + h};
            } else if constexpr (std::is_same_v<T, Obb>) {
                return Obb{v.center, v.rotation, s * v.half_extents};
            } else if constexpr (std::is_same_v<T, Sphere>) {
                return Sphere{v.center, s * v.radius};
            } else {
                const Vec3 c = v.center();
                return Capsule{c + s * (v.p0 - c), c + s * (v.p1 - c), s * v.radius};
            }
        },
        bv);
}

/// The BV scaled by `s` about the origin (the whole configuration zoomed).
BoundingVolume zoomed(const BoundingVolume& bv, double s) {
    return std::visit(
        [&](const auto& v) -> BoundingVolume {
            using T = std::decay_t<decltype(v)>;
            if constexpr (std::is_same_v<T, Aabb>) return Aabb{s * v.min, s * v.max};
            else if constexpr (std::is_same_v<T, Obb>) return Obb{s * v.center, v.rotation, s * v.half_extents};
            else if constexpr (std::is_same_v<T, Sphere>) return Sphere{s * v.center, s * v.radius};
            else return Capsule{s * v.p0, s * v.p1, s * v.radius};
        },
        bv);
}

/// The BV translated by `offset` (rounded as any move far from the origin is).
BoundingVolume translated(const BoundingVolume& bv, const Vec3& offset) {
    return std::visit(
        [&](const auto& v) -> BoundingVolume {
            using T = std::decay_t<decltype(v)>;
            if constexpr (std::is_same_v<T, Aabb>) return Aabb{v.min + offset, v.max + offset};
            else if constexpr (std::is_same_v<T, Obb>) return Obb{v.center + offset, v.rotation, v.half_extents};
            else if constexpr (std::is_same_v<T, Sphere>) return Sphere{v.center + offset, v.radius};
            else return Capsule{v.p0 + offset, v.p1 + offset, v.radius};
        },
        bv);
}

/// A random point of the BV (not uniform; any point will do for nesting).
Vec3 random_point_in(SplitMix64& rng, const BoundingVolume& bv) {
    const Vec3 u(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    return std::visit(
        [&](const auto& v) -> Vec3 {
            using T = std::decay_t<decltype(v)>;
            if constexpr (std::is_same_v<T, Aabb>) return v.center() + v.half_extents().cwiseProduct(u);
            else if constexpr (std::is_same_v<T, Obb>) return v.center + v.rotation * v.half_extents.cwiseProduct(u);
            else if constexpr (std::is_same_v<T, Sphere>) return v.center + v.radius * u / std::sqrt(3.0);
            else return v.p0 + rng.uniform() * (v.p1 - v.p0) + v.radius * u / std::sqrt(3.0);
        },
        bv);
}

struct PairStats {
    int disjoint = 0, overlapping = 0, ambiguous = 0, inconsistent = 0, disagreements = 0;
    std::string first_failure;
};

/// Centre, axes and half extents of a box kind (Aabb: identity axes).
struct BoxFrame {
    Vec3 center;
    Mat3 axes;
    Vec3 half;
};

BoxFrame box_frame(const BoundingVolume& bv) {
    if (const auto* box = std::get_if<Aabb>(&bv)) return {box->center(), Mat3::Identity(), box->half_extents()};
    const Obb& box = std::get<Obb>(bv);
    return {box.center, box.rotation, box.half_extents};
}

/// A box of kind `type` (an Aabb needs identity axes) from its frame.
BoundingVolume box_of(BvType type, const BoxFrame& f) {
    if (type == BvType::aabb) return Aabb{f.center - f.half, f.center + f.half};
    return Obb{f.center, f.axes, f.half};
}

/// Box B against one of box A's faces, the faces parallel and overlapping sideways, B's centre at
/// (1 + gap) x the touching distance along the face normal. B is turned about that normal when it is an
/// Obb (A is then an Obb too, or an Aabb with B an Obb: the normal is a world axis either way).
BoundingVolume face_against(SplitMix64& rng, const BoundingVolume& a, BvType tb, double gap) {
    const BoxFrame fa = box_frame(a);
    const int k = static_cast<int>(rng.below(3));
    const Mat3 turn = tb == BvType::obb ? Mat3(Eigen::AngleAxisd(rng.uniform(0, 6.3), Vec3::Unit(k)).toRotationMatrix())
                                        : Mat3::Identity();
    const Vec3 half = Vec3(log_uniform(rng, 0.05, 1.0), log_uniform(rng, 0.05, 1.0), log_uniform(rng, 0.05, 1.0));
    Vec3 local(rng.uniform(-fa.half.x(), fa.half.x()), rng.uniform(-fa.half.y(), fa.half.y()),
               rng.uniform(-fa.half.z(), fa.half.z()));
    local[k] = (rng.uniform() < 0.5 ? -1.0 : 1.0) * (fa.half[k] + half[k]) * (1.0 + gap);
    return box_of(tb, {fa.center + fa.axes * local, fa.axes * turn, half});
}

/// A box of kind `tb` (random axes if an Obb) containing box A, up to `factor` - 1 larger than needed.
BoundingVolume box_around(SplitMix64& rng, const BoundingVolume& a, BvType tb) {
    const BoxFrame fa = box_frame(a);
    const Mat3 axes = tb == BvType::obb ? rng.rotation() : fa.axes;  // an Aabb around an Aabb
    // A's half-width along each of B's axes: sum_j |B_i . A_j| * ea_j.
    const Vec3 reach = (axes.transpose() * fa.axes).cwiseAbs() * fa.half;
    return box_of(tb, {fa.center, axes, reach * log_uniform(rng, 1.001, 3.0) + Vec3::Constant(1e-3)});
}

constexpr bool is_box(BvType type) { return type == BvType::aabb || type == BvType::obb; }

/// One pair of kinds over `count` seeded configurations: 35% random placements, 35% near-touching
/// (B scaled about its centre to (1 +- 1e-6) of the scale at which overlaps() flips), 10% (box pairs;
/// near-touching otherwise) faces parallel at (1 +- 1e-6) of the touching distance, 20% nested (B small
/// inside A, or for two boxes half the time A inside B); for OBB-OBB a fifth share a box axis (parallel
/// edges). Each configuration is zoomed by 1e-3..1e3 and then moved by `offset` (a random direction):
/// far from the origin the zoom starts at 1e-4 x offset, where 1e-6 of the size is still far more than
/// the coordinates' rounding.
PairStats run_pair(BvType ta, BvType tb, int count, std::uint64_t seed, double offset = 0.0) {
    SplitMix64 rng(seed);
    PairStats stats;
    const bool box_pair = is_box(ta) && is_box(tb);
    for (int n = 0; n < count; ++n) {
        BoundingVolume a = random_volume(rng, ta, Vec3::Zero(), 1.0);
        BoundingVolume b;
        // Parallel edges, the SAT's degenerate case: B's axes are A's turned about one of A's axes.
        const bool share_axis = ta == BvType::obb && tb == BvType::obb && rng.uniform() < 0.2;
        const Mat3 shared_rotation =
            share_axis ? Mat3(std::get<Obb>(a).rotation *
                              Eigen::AngleAxisd(rng.uniform(0, 6.3), Vec3::Unit(static_cast<int>(rng.below(3)))).toRotationMatrix())
                       : Mat3::Identity();
        const auto align = [&](BoundingVolume& bv) {
            if (share_axis) std::get<Obb>(bv).rotation = shared_rotation;
        };
        const double mode = rng.uniform();
        if (mode < 0.35) {
            b = random_volume(rng, tb, Vec3(rng.uniform(-2, 2), rng.uniform(-2, 2), rng.uniform(-2, 2)), 1.0);
            align(b);
        } else if (mode < 0.7 || (mode < 0.8 && !box_pair)) {
            // Bisect the scale at which overlaps() flips; B's centre must lie outside A so that scale 0
            // is disjoint.
            b = random_volume(rng, tb, Vec3(rng.uniform(-2.5, 2.5), rng.uniform(-2.5, 2.5), rng.uniform(-2.5, 2.5)), 1.0);
            align(b);
            if (overlaps(a, scaled(b, 0.0))) {
                --n;
                continue;
            }
            double lo = 0.0, hi = 1.0;
            while (!overlaps(a, scaled(b, hi)) && hi < 1e6) hi *= 2.0;
            if (hi >= 1e6) {
                --n;
                continue;
            }
            for (int k = 0; k < 80 && hi - lo > 1e-15 * hi; ++k) {
                const double mid = 0.5 * (lo + hi);
                (overlaps(a, scaled(b, mid)) ? hi : lo) = mid;
            }
            b = scaled(b, hi * (rng.uniform() < 0.5 ? 1.0 - 1e-6 : 1.0 + 1e-6));
        } else if (mode < 0.8) {
            b = face_against(rng, a, tb, rng.uniform() < 0.5 ? -1e-6 : 1e-6);
        } else if (box_pair && rng.uniform() < 0.5) {
            b = box_around(rng, a, tb);
        } else {
            const double small = log_uniform(rng, 0.01, 0.3);
            b = random_volume(rng, tb, random_point_in(rng, a), small);
            align(b);
        }
        // The whole configuration at a random scale and place: every test and the band are relative.
        const double zoom = log_uniform(rng, std::max(1e-3, 1e-4 * offset), 1e3);
        const Vec3 origin = offset * rng.rotation().col(0);
        a = translated(zoomed(a, zoom), origin);
        b = translated(zoomed(b, zoom), origin);
        const bool ours = overlaps(a, b);
        // The std::visit dispatch must agree with the direct overload.
        if (ours != overlaps(BoundingVolume(a), BoundingVolume(b))) ++stats.disagreements;
        switch (oracle(a, b, origin)) {
            case Verdict::disjoint:
                ++stats.disjoint;
                if (ours) ++stats.disagreements;
                break;
            case Verdict::overlapping:
                ++stats.overlapping;
                if (!ours) ++stats.disagreements;
                break;
            case Verdict::ambiguous: ++stats.ambiguous; break;
            case Verdict::inconsistent: ++stats.inconsistent; break;
        }
        if (stats.disagreements > 0 && stats.first_failure.empty())
            stats.first_failure = "configuration " + std::to_string(n) + ", ours=" + std::to_string(ours);
    }
    return stats;
}

/// 100 000 per pair by default; HBVH_ORACLE_CONFIGURATIONS overrides it for longer soak runs.
int configurations_per_pair() {
    static const int count = [] {
        const char* text = std::getenv("HBVH_ORACLE_CONFIGURATIONS");
        return text != nullptr ? std::max(1000, std::atoi(text)) : 100000;
    }();
    return count;
}

/// A pair of kinds and how far from the origin its configurations sit.
struct OracleCase {
    BvType a, b;
    double offset;
};

class OverlapOracle : public ::testing::TestWithParam<OracleCase> {};

TEST_P(OverlapOracle, AgreesWithLibccdOutsideTheBand) {
    const auto [ta, tb, offset] = GetParam();
    // Away from the origin a fifth of the configurations: the same code, only the coordinates differ.
    const int count = offset > 0.0 ? configurations_per_pair() / 5 : configurations_per_pair();
    const unsigned kinds = 16u * static_cast<unsigned>(ta) + static_cast<unsigned>(tb);
    const unsigned place = offset > 0.0 ? 0x100u * static_cast<unsigned>(std::log10(offset)) : 0u;
    const PairStats s = run_pair(ta, tb, count, 0x5eed0000u + kinds + place, offset);
    RecordProperty("disjoint", s.disjoint);
    RecordProperty("overlapping", s.overlapping);
    RecordProperty("ambiguous", s.ambiguous);
    RecordProperty("disagreements", s.disagreements);
    std::printf("[ oracle ] %s-%s at %g: disjoint %d overlapping %d ambiguous %d disagreements %d\n",
                std::string(to_string(ta)).c_str(), std::string(to_string(tb)).c_str(), offset, s.disjoint, s.overlapping,
                s.ambiguous, s.disagreements);
    EXPECT_EQ(s.disagreements, 0) << s.first_failure;
    EXPECT_EQ(s.inconsistent, 0);
    // The band must stay narrow: near-touching cases (1e-6) are decided, not skipped.
    EXPECT_LT(s.ambiguous, count / 100);
    EXPECT_GT(s.disjoint, count / 10);
    EXPECT_GT(s.overlapping, count / 10);
}

std::string case_name(const ::testing::TestParamInfo<OracleCase>& info) {
    const std::string at = info.param.offset > 0.0 ? "_at_1e" + std::to_string(static_cast<int>(std::log10(info.param.offset))) : "";
    return std::string(to_string(info.param.a)) + "_" + std::string(to_string(info.param.b)) + at;
}

std::vector<OracleCase> oracle_cases() {
    const std::pair<BvType, BvType> kinds[] = {
        {BvType::aabb, BvType::aabb},       {BvType::aabb, BvType::obb},         {BvType::aabb, BvType::sphere},
        {BvType::aabb, BvType::capsule},    {BvType::obb, BvType::obb},          {BvType::obb, BvType::sphere},
        {BvType::obb, BvType::capsule},     {BvType::sphere, BvType::sphere},    {BvType::sphere, BvType::capsule},
        {BvType::capsule, BvType::capsule}};
    std::vector<OracleCase> cases;
    for (const double offset : {0.0, 1e3, 1e5})
        for (const auto& [a, b] : kinds) cases.push_back({a, b, offset});
    return cases;
}

INSTANTIATE_TEST_SUITE_P(AllPairs, OverlapOracle, ::testing::ValuesIn(oracle_cases()), case_name);

// Dense brute force for the distance kernels.

/// Golden-section minimum of a convex function on [0, 1] (to ~1e-12 in t).
template <class F>
double golden_minimum(F f) {
    const double g = 0.5 * (std::sqrt(5.0) - 1.0);
    double lo = 0.0, hi = 1.0;
    double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo), f1 = f(x1), f2 = f(x2);
    for (int k = 0; k < 90; ++k) {
        if (f1 <= f2) {
            hi = x2, x2 = x1, f2 = f1, x1 = hi - g * (hi - lo), f1 = f(x1);
        } else {
            lo = x1, x1 = x2, f1 = f2, x2 = lo + g * (hi - lo), f2 = f(x2);
        }
    }
    return std::min({f(0.0), f(1.0), f1, f2});
}

double brute_point_box(const Vec3& p, const Vec3& h) { return (p - p.cwiseMax(-h).cwiseMin(h)).norm(); }

double brute_point_segment(const Vec3& p, const Vec3& a, const Vec3& b) {
    return golden_minimum([&](double t) { return (a + t * (b - a) - p).norm(); });
}

TEST(SegmentBoxDistance, MatchesGoldenSectionOnConvexDistance) {
    SplitMix64 rng(77);
    int mismatches = 0;
    for (int n = 0; n < 20000; ++n) {
        const Vec3 h(rng.uniform(0, 1), rng.uniform(0, 1), rng.uniform(0, 1));
        const Vec3 p0(rng.uniform(-2, 2), rng.uniform(-2, 2), rng.uniform(-2, 2));
        // Some segments axis-parallel or degenerate, to reach the special cases.
        Vec3 p1(rng.uniform(-2, 2), rng.uniform(-2, 2), rng.uniform(-2, 2));
        if (n % 7 == 0) p1[n % 3] = p0[n % 3];
        if (n % 101 == 0) p1 = p0;
        // The distance (not squared) is convex along the segment, so golden section finds its minimum.
        const double expected = golden_minimum([&](double t) { return brute_point_box(p0 + t * (p1 - p0), h); });
        const double ours = std::sqrt(segment_box_squared_distance(p0, p1, h));
        if (std::abs(ours - expected) > 1e-9) ++mismatches;
    }
    EXPECT_EQ(mismatches, 0);
}

TEST(SegmentSegmentDistance, MatchesGoldenSectionIncludingParallel) {
    SplitMix64 rng(78);
    int mismatches = 0;
    for (int n = 0; n < 5000; ++n) {
        const Vec3 p0(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
        const Vec3 p1(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
        Vec3 q0(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
        Vec3 q1(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
        if (n % 3 == 0) q1 = q0 + rng.uniform(-2, 2) * (p1 - p0);                 // exactly parallel
        if (n % 3 == 1) q1 = q0 + (p1 - p0) + 1e-9 * Vec3(rng.uniform(), 0, 0);  // nearly parallel
        if (n % 50 == 0) q1 = q0;                                                 // a point
        // dist(seg1(s), seg2) is convex in s: golden section over s of the inner golden section.
        const double expected = golden_minimum([&](double s) { return brute_point_segment(p0 + s * (p1 - p0), q0, q1); });
        const double ours = std::sqrt(segment_segment_squared_distance(p0, p1, q0, q1));
        if (std::abs(ours - expected) > 1e-9) ++mismatches;
    }
    EXPECT_EQ(mismatches, 0);
}

// Hand-made touching, separated and nested cases.

/// Unit cube [0, 1]^3 in each box form, and a sphere/capsule family that touches its x = 1 face.
const Aabb unit_box{Vec3(0, 0, 0), Vec3(1, 1, 1)};
const Obb unit_obb = Obb::from_aabb(unit_box);

TEST(OverlapCases, TouchingSeparatedNested) {
    const double tiny = 1e-12;
    // Box - box: shared face, a gap, nested, and a rotated box touching at a corner.
    EXPECT_TRUE(overlaps(unit_box, Aabb{Vec3(1, 0, 0), Vec3(2, 1, 1)}));
    EXPECT_FALSE(overlaps(unit_box, Aabb{Vec3(1 + tiny, 0, 0), Vec3(2, 1, 1)}));
    EXPECT_TRUE(overlaps(unit_box, Aabb{Vec3(0.25, 0.25, 0.25), Vec3(0.5, 0.5, 0.5)}));
    EXPECT_TRUE(overlaps(unit_box, Obb{Vec3(2, 0.5, 0.5), Mat3::Identity(), Vec3(1, 0.5, 0.5)}));
    EXPECT_FALSE(overlaps(unit_box, Obb{Vec3(2 + tiny, 0.5, 0.5), Mat3::Identity(), Vec3(1, 0.5, 0.5)}));
    EXPECT_TRUE(overlaps(unit_obb, Obb{Vec3(0.5, 0.5, 0.5), Mat3::Identity(), Vec3(0.1, 0.1, 0.1)}));
    {
        // A box rotated 45 degrees about z whose edge touches the cube's x = 1 face: edge axes are parallel.
        const Mat3 r = Eigen::AngleAxisd(std::numbers::pi / 4, Vec3::UnitZ()).toRotationMatrix();
        const double reach = std::sqrt(0.5);
        EXPECT_TRUE(overlaps(unit_obb, Obb{Vec3(1 + reach - 1e-9, 0.5, 0.5), r, Vec3(0.5, 0.5, 0.5)}));
        EXPECT_FALSE(overlaps(unit_obb, Obb{Vec3(1 + reach + 1e-9, 0.5, 0.5), r, Vec3(0.5, 0.5, 0.5)}));
    }
    // Sphere.
    EXPECT_TRUE(overlaps(unit_box, Sphere{Vec3(2, 0.5, 0.5), 1.0}));
    EXPECT_FALSE(overlaps(unit_box, Sphere{Vec3(2, 0.5, 0.5), 1.0 - tiny}));
    EXPECT_TRUE(overlaps(unit_obb, Sphere{Vec3(0.5, 0.5, 0.5), 0.01}));
    EXPECT_TRUE(overlaps(unit_obb, Sphere{Vec3(2, 0.5, 0.5), 1.0}));
    EXPECT_FALSE(overlaps(unit_obb, Sphere{Vec3(2, 0.5, 0.5), 1.0 - tiny}));
    EXPECT_TRUE(overlaps(Sphere{Vec3(0, 0, 0), 1.0}, Sphere{Vec3(3, 0, 0), 2.0}));
    EXPECT_FALSE(overlaps(Sphere{Vec3(0, 0, 0), 1.0}, Sphere{Vec3(3, 0, 0), 2.0 - tiny}));
    EXPECT_TRUE(overlaps(Sphere{Vec3(0, 0, 0), 1.0}, Sphere{Vec3(0.1, 0, 0), 0.1}));
    // Capsule: along the face, beyond a corner (where an inflated-box test would wrongly say yes), nested.
    EXPECT_TRUE(overlaps(unit_box, Capsule{Vec3(1.5, -1, 0.5), Vec3(1.5, 2, 0.5), 0.5}));
    EXPECT_FALSE(overlaps(unit_box, Capsule{Vec3(1.5, -1, 0.5), Vec3(1.5, 2, 0.5), 0.5 - tiny}));
    {
        const Vec3 corner(1, 1, 1), out = Vec3(1, 1, 1).normalized();
        // Segment perpendicular to the corner's diagonal, at distance 0.3 from the corner.
        const Vec3 mid = corner + 0.3 * out, along = Vec3(1, -1, 0).normalized();
        const Capsule c{mid - along, mid + along, 0.3 - 1e-9};
        EXPECT_FALSE(overlaps(unit_box, c));
        EXPECT_FALSE(overlaps(unit_obb, c));
        EXPECT_TRUE(overlaps(unit_obb, Capsule{c.p0, c.p1, 0.3 + 1e-9}));
    }
    EXPECT_TRUE(overlaps(unit_obb, Capsule{Vec3(0.4, 0.5, 0.5), Vec3(0.6, 0.5, 0.5), 0.05}));
    EXPECT_TRUE(overlaps(Sphere{Vec3(0, 2, 0), 1.0}, Capsule{Vec3(-1, 0, 0), Vec3(1, 0, 0), 1.0}));
    EXPECT_FALSE(overlaps(Sphere{Vec3(0, 2, 0), 1.0 - tiny}, Capsule{Vec3(-1, 0, 0), Vec3(1, 0, 0), 1.0}));
    EXPECT_TRUE(overlaps(Sphere{Vec3(0, 0, 0), 0.01}, Capsule{Vec3(-1, 0, 0), Vec3(1, 0, 0), 1.0}));
    // Capsule - capsule: parallel side by side, crossing, collinear end to end, degenerate (points).
    EXPECT_TRUE(overlaps(Capsule{Vec3(0, 0, 0), Vec3(1, 0, 0), 0.5}, Capsule{Vec3(0.5, 1, 0), Vec3(3, 1, 0), 0.5}));
    EXPECT_FALSE(overlaps(Capsule{Vec3(0, 0, 0), Vec3(1, 0, 0), 0.5}, Capsule{Vec3(0.5, 1, 0), Vec3(3, 1, 0), 0.5 - tiny}));
    EXPECT_TRUE(overlaps(Capsule{Vec3(0, 0, 0), Vec3(1, 0, 0), 0.5}, Capsule{Vec3(2, 0, 0), Vec3(3, 0, 0), 0.5}));
    EXPECT_FALSE(overlaps(Capsule{Vec3(0, 0, 0), Vec3(1, 0, 0), 0.5}, Capsule{Vec3(2, 0, 0), Vec3(3, 0, 0), 0.5 - tiny}));
    EXPECT_TRUE(overlaps(Capsule{Vec3(0, 0, 0), Vec3(0, 0, 0), 1.0}, Capsule{Vec3(2, 0, 0), Vec3(2, 0, 0), 1.0}));
    EXPECT_FALSE(overlaps(Capsule{Vec3(0, 0, 0), Vec3(0, 0, 0), 1.0}, Capsule{Vec3(2, 0, 0), Vec3(2, 0, 0), 1.0 - tiny}));
    EXPECT_TRUE(overlaps(Capsule{Vec3(-1, 0, 0), Vec3(1, 0, 0), 0.1}, Capsule{Vec3(0, -1, 0.2), Vec3(0, 1, 0.2), 0.1}));
    EXPECT_FALSE(overlaps(Capsule{Vec3(-1, 0, 0), Vec3(1, 0, 0), 0.1}, Capsule{Vec3(0, -1, 0.2), Vec3(0, 1, 0.2), 0.1 - tiny}));
    EXPECT_TRUE(overlaps(Capsule{Vec3(-1, 0, 0), Vec3(1, 0, 0), 1.0}, Capsule{Vec3(0, 0, 0), Vec3(0.1, 0, 0), 0.1}));
}

/// boxes_may_overlap (the traversal's inner box test) in the frame of box a, as the traversal forms it:
/// b's axes moved by a rigid motion first, then taken into a's frame; the coordinates it must cover are
/// a's centre, b's model centre and the motion's translation.
bool may_overlap(const Obb& a, const Obb& b_model, const RigidTransform& t) {
    const Mat3 moved_axes = t.rotation * b_model.rotation;
    const Mat3 at = a.rotation.transpose();
    const double coordinates =
        a.center.cwiseAbs().sum() + b_model.center.cwiseAbs().sum() + t.translation.cwiseAbs().sum();
    return boxes_may_overlap(a.half_extents, b_model.half_extents, at * moved_axes,
                             at * (t.apply(b_model.center) - a.center), coordinates);
}

/// One offset's share of NeverRejectsAnExactOverlapIncludingTouching: a at `offset` in a random direction,
/// b's model frame at the origin, moved next to a; counts of exact overlaps and of pruned separated pairs.
std::pair<int, int> may_overlap_run(SplitMix64& rng, double offset, int count) {
    int overlapping = 0, rejected_separated = 0;
    for (int n = 0; n < count; ++n) {
        const double zoom = log_uniform(rng, 1e-3, 1e3);
        const Vec3 origin = offset * rng.rotation().col(0);
        Obb a = std::get<Obb>(zoomed(random_volume(rng, BvType::obb, Vec3::Zero(), 1.0), zoom));
        a.center += origin;
        const Obb b_model = std::get<Obb>(random_volume(rng, BvType::obb, Vec3::Zero(), zoom));
        const Vec3 direction = rng.rotation().col(0);
        const RigidTransform spin{rng.rotation(), Vec3::Zero()};
        // Slide b along `direction` to the distance where the exact test flips (bisection), then test
        // just inside that distance (touching up to rounding) and at random distances.
        const auto at = [&](double d) { return RigidTransform{spin.rotation, origin + d * direction}; };
        const auto exact = [&](double d) { return overlaps(a, b_model.transformed(at(d))); };
        double lo = 0.0, hi = 4.0 * zoom;
        if (!exact(lo) || exact(hi)) continue;
        for (int k = 0; k < 80; ++k) (exact(0.5 * (lo + hi)) ? lo : hi) = 0.5 * (lo + hi);
        for (const double d : {lo, lo * (1 - 1e-12), rng.uniform(0.0, hi), hi * (1 + 1e-3), rng.uniform(hi, 4 * zoom)}) {
            const bool real = exact(d);
            const bool maybe = may_overlap(a, b_model, at(d));
            if (real) {
                ++overlapping;
                EXPECT_TRUE(maybe) << "config " << n << " at " << offset << " distance " << d;
            } else if (!maybe) {
                ++rejected_separated;
            }
        }
    }
    return {overlapping, rejected_separated};
}

TEST(BoxesMayOverlap, NeverRejectsAnExactOverlapIncludingTouching) {
    SplitMix64 rng(4242);
    for (const double offset : {0.0, 1e3, 1e5}) {
        const auto [overlapping, rejected_separated] = may_overlap_run(rng, offset, 10000);
        EXPECT_GT(overlapping, 10000) << "at " << offset;
        // Face axes separate most separated pairs: the test must still prune.
        EXPECT_GT(rejected_separated, 5000) << "at " << offset;
    }
    // Separated along a face axis of either box: rejected; separated only along an edge-edge axis: not.
    const Obb unit{Vec3::Zero(), Mat3::Identity(), Vec3::Ones()};
    EXPECT_FALSE(may_overlap(unit, unit, RigidTransform{Mat3::Identity(), Vec3(2.0 + 1e-9, 0, 0)}));
    EXPECT_TRUE(may_overlap(unit, unit, RigidTransform{Mat3::Identity(), Vec3(2.0, 0, 0)}));
}

// Touching far from the origin.

/// A rigid motion to `offset` in a random direction, randomly turned (or only translated, for Aabbs).
RigidTransform far_motion(SplitMix64& rng, double offset, bool turn) {
    return {turn ? rng.rotation() : Mat3::Identity(), offset * rng.rotation().col(0)};
}

/// The BV moved by `m`; an Aabb stays an Aabb when m only translates (then it is exact up to rounding).
BoundingVolume moved(const BoundingVolume& bv, const RigidTransform& m) {
    if (const auto* box = std::get_if<Aabb>(&bv); box != nullptr && m.rotation == Mat3::Identity())
        return Aabb{box->min + m.translation, box->max + m.translation};
    return transformed(bv, m);
}

/// Pairs that touch in their local frame, of size `s` (a power of two, so that every coordinate below is
/// exact; the radii q sqrt 2 are rounded to nearest), placed near the origin of that frame.
std::vector<std::pair<BoundingVolume, BoundingVolume>> touching_pairs(SplitMix64& rng, double s) {
    const double h = s * 0.5, q = s * 0.25, diagonal = q * std::numbers::sqrt2;
    const Aabb base_box{Vec3(-h, -h, -q), Vec3(h, h, q)};
    const Obb base = Obb::from_aabb(base_box);
    // A box on base's top face z = q, turned about z by a random angle (its faces stay parallel).
    const Mat3 yaw = Eigen::AngleAxisd(rng.uniform(0, 6.3), Vec3::UnitZ()).toRotationMatrix();
    const Capsule rod{Vec3(-h, 0, 0), Vec3(h, 0, 0), q};
    return {
        {base_box, Aabb{Vec3(-q, -q, q), Vec3(h, q, h)}},                           // box face on box face
        {base, Obb{Vec3(q, -q, q + q), yaw, Vec3(q, q, q)}},                         // turned box on box face
        {base_box, Sphere{Vec3(q, 0, q + q), q}},                                    // sphere on a box face
        {base, Sphere{Vec3(h + q, h + q, 0), diagonal}},                             // sphere on a box edge
        {base_box, Capsule{Vec3(-h, 0, q + q), Vec3(h, q, q + q), q}},               // capsule lying on a box
        {base, Capsule{Vec3(h + q, -h, q + q), Vec3(h + q, h, q + q), diagonal}},    // capsule on a box edge
        {Sphere{Vec3::Zero(), h}, Sphere{Vec3(0, 0, h + q), q}},                     // sphere on sphere
        {rod, Capsule{Vec3(0, -h, h), Vec3(0, h, h), q}},                            // crossed capsules
        {rod, Capsule{Vec3(-q, 0, h), Vec3(h, 0, h), q}},                            // parallel capsules
        {rod, Sphere{Vec3(h, 0, h), q}},                                             // sphere on a capsule
    };
}

TEST(OverlapFarFromTheOrigin, TouchingPairsStayTouching) {
    // Moved kilometres away, touching pairs arrive apart or overlapping by ulps of their coordinates,
    // however small they are: overlaps() must still call them touching. (Without the coordinate slacks
    // some of these fail: boxes face to face at 1e5, the round tests at any offset >= 1e3.)
    SplitMix64 rng(91);
    int checked = 0, missed = 0;
    for (const double offset : {1.0, 1e3, 1e5}) {
        for (int n = 0; n < 300; ++n) {
            const double size = std::ldexp(1.0, -static_cast<int>(rng.below(11)));  // 1 down to ~1e-3
            const RigidTransform m = far_motion(rng, offset, n % 2 == 0);
            for (const auto& [a, b] : touching_pairs(rng, size)) {
                const BoundingVolume ma = moved(a, m), mb = moved(b, m);
                ++checked;
                if (!overlaps(ma, mb) || !overlaps(mb, ma)) {
                    ++missed;
                    ADD_FAILURE() << "offset " << offset << " size " << size << " kinds " << to_string(type_of(a))
                                  << "-" << to_string(type_of(b)) << " (pair " << n << ")";
                    if (missed > 10) return;
                }
            }
        }
    }
    EXPECT_GT(checked, 5000);
}

TEST(OverlapFarFromTheOrigin, SlackStaysWithinTheBand) {
    // The slack is a band of ~1e-13 of the coordinates (L1 norms) at most: gaps of 1e-12 of the coordinates
    // plus 1e-12 of the size are still separated, at every offset.
    SplitMix64 rng(92);
    for (const double offset : {1.0, 1e3, 1e5}) {
        for (int n = 0; n < 200; ++n) {
            const double size = log_uniform(rng, 1e-3, 1.0);
            const RigidTransform m = far_motion(rng, offset, n % 2 == 0);
            const double gap = 1e-12 * (3.0 * offset + size) * 4.0;
            const BoundingVolume box = moved(Aabb{Vec3(-size, -size, -size), Vec3(size, size, size)}, m);
            const Vec3 normal = m.rotation.col(0);
            const Vec3 face = m.apply(Vec3(size, 0, 0));
            const BoundingVolume sphere = Sphere{face + (0.5 * size + gap) * normal, 0.5 * size};
            EXPECT_FALSE(overlaps(box, sphere)) << offset << " " << size;
            const Obb other{face + (0.5 * size + gap) * normal, m.rotation, Vec3::Constant(0.5 * size)};
            EXPECT_FALSE(overlaps(box, BoundingVolume(other))) << offset << " " << size;
            const Sphere ball{m.apply(Vec3::Zero()), size};
            EXPECT_FALSE(overlaps(Sphere{ball.center + (2.0 * size + gap) * normal, size}, ball)) << offset;
        }
    }
}

}  // namespace
}  // namespace hbvh
