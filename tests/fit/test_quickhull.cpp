// SPDX-License-Identifier: MIT
// The fitters' own quickhull (src/fit/quickhull.hpp), held to two oracles: brute force (every point lies
// below every face of the returned surface, which closes up as a sphere of triangles, so the surface is the
// boundary of the points' hull) and qhull (the same hull vertices, and through summarize_hull the same
// surface covariance and face normals), on general sets and on the degenerate ones models are made of:
// box corners sharing planes, lattices, flat and collinear sets, clusters far from the origin.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <set>
#include <string>
#include <vector>

#include "../../src/fit/convex_hull.hpp"
#include "../../src/fit/frames.hpp"
#include "../../src/fit/hull_2d.hpp"
#include "../../src/fit/quickhull.hpp"
#include "hbvh/geometry/bounding_volume.hpp"
#include "hbvh/scene/generate.hpp"

namespace hbvh {
namespace {

using detail::TriangleHull;

std::vector<Sphere> as_spheres(const std::vector<Vec3>& points) {
    std::vector<Sphere> spheres;
    for (const Vec3& p : points) spheres.push_back({p, 0.0});
    return spheres;
}

/// Named point sets: random in a ball, on a sphere, the generating spheres' centres of random scenes (box
/// corners, many sharing planes), a 4x4x4 lattice, a thin slab and a cluster far from the origin.
std::map<std::string, std::vector<Vec3>> solid_sets() {
    std::map<std::string, std::vector<Vec3>> sets;
    SplitMix64 rng(4242);
    for (std::size_t n : {4, 5, 12, 40, 200, 1000}) {
        std::vector<Vec3>& ball = sets["ball_" + std::to_string(n)];
        while (ball.size() < n) {
            const Vec3 p(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
            if (p.norm() <= 1.0) ball.push_back(p);
        }
        std::vector<Vec3>& shell = sets["sphere_" + std::to_string(n)];
        while (shell.size() < n) {
            const Vec3 p(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
            if (p.norm() > 0.1) shell.push_back(p.normalized() * 3.0);
        }
    }
    for (std::uint32_t count : {1u, 2u, 5u, 16u, 60u}) {
        for (std::uint64_t seed = 1; seed <= 6; ++seed) {
            SceneOptions options;
            options.count = count;
            options.seed = seed;
            std::vector<Sphere> spheres;
            for (const Primitive& p : generate_scene(options)) append_generating_spheres(p.volume, spheres);
            std::vector<Vec3>& points = sets["scene_" + std::to_string(count) + "_" + std::to_string(seed)];
            for (const Sphere& s : spheres) points.push_back(s.center);
        }
    }
    std::vector<Vec3>& lattice = sets["lattice"];
    for (int x = 0; x < 4; ++x)
        for (int y = 0; y < 4; ++y)
            for (int z = 0; z < 4; ++z) lattice.emplace_back(x, y, z);
    std::vector<Vec3>& slab = sets["slab"];
    for (int i = 0; i < 50; ++i) slab.emplace_back(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(0, 1e-6));
    std::vector<Vec3>& far = sets["far_cluster"];
    for (int i = 0; i < 50; ++i)
        far.push_back(Vec3(1e6, -2e6, 3e6) + Vec3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)));
    // Axis-aligned unit boxes on a grid: every face plane shared by many corners.
    std::vector<Vec3>& boxes = sets["box_grid"];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            for (int corner = 0; corner < 8; ++corner)
                boxes.emplace_back(2.0 * i + (corner & 1), 2.0 * j + ((corner >> 1) & 1), (corner >> 2) & 1);
    return sets;
}

double scale_of(const std::vector<Vec3>& points) {
    double scale = 0.0;
    for (const Vec3& p : points) scale = std::max(scale, p.cwiseAbs().sum());
    return scale;
}

/// Brute force: the triangles close up (every directed edge has its reverse, each once), and every point is
/// below every face's plane within `slack`, so the surface is the boundary of the points' convex hull.
void expect_hull_of(const std::vector<Vec3>& points, const TriangleHull& hull, double slack, const std::string& name) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
    for (const auto& t : hull.triangles)
        for (int k = 0; k < 3; ++k) ++edges[{t[static_cast<std::size_t>(k)], t[static_cast<std::size_t>((k + 1) % 3)]}];
    for (const auto& [edge, count] : edges) {
        EXPECT_EQ(count, 1) << name;
        EXPECT_EQ(edges.count({edge.second, edge.first}), 1u) << name << ": an edge without its twin";
    }
    // The signed volume, from one of the hull's corners so that nothing far away enters the rounding, and
    // its rounding error's bound: a flat set's hull (a nanometre box beside a far point) has a volume below it,
    // and then its sign says nothing.
    const Vec3& origin = points[hull.triangles.front()[0]];
    double volume = 0.0;
    double rounding = 0.0;
    for (const auto& t : hull.triangles) {
        const Vec3 a = points[t[0]] - origin;
        const Vec3 b = points[t[1]] - origin;
        const Vec3 c = points[t[2]] - origin;
        rounding += 8.0 * std::numeric_limits<double>::epsilon() * a.norm() * b.norm() * c.norm() / 6.0;
        const Vec3 n = (b - a).cross(c - a).normalized();
        double above = -1.0;
        for (const Vec3& p : points) above = std::max(above, n.dot(p - origin - a));
        EXPECT_LE(above, slack) << name << ": a point above a face";
        volume += a.dot(b.cross(c)) / 6.0;
    }
    EXPECT_GT(volume, -rounding) << name << ": the faces point inwards";
}

/// Centres the points, as summarize_hull does before it calls the hull.
std::vector<Vec3> centred(std::vector<Vec3> points) {
    Vec3 mean = Vec3::Zero();
    for (const Vec3& p : points) mean += p;
    mean /= static_cast<double>(points.size());
    for (Vec3& p : points) p -= mean;
    return points;
}

/// `points` centred as summarize_hull centres them, then the hull; a hull returned is held to brute force
/// (expect_hull_of). True when quickhull returned one rather than declining.
bool hull_checked_if_solved(const std::vector<Vec3>& points, const std::string& name) {
    const std::vector<Vec3> shifted = centred(points);
    const std::optional<TriangleHull> hull = detail::quickhull(shifted);
    if (hull) expect_hull_of(shifted, *hull, 1e-10 * scale_of(shifted), name);
    return hull.has_value();
}

TEST(Quickhull, EveryPointBelowEveryFaceOfAClosedSurface) {
    int solved = 0;
    int solids = 0;  // the sets qhull finds a solid hull for
    for (const auto& [name, raw] : solid_sets()) {
        solids += detail::summarize_hull(as_spheres(raw), detail::HullMethod::qhull).is_solid ? 1 : 0;
        const std::vector<Vec3> points = centred(raw);
        const std::optional<TriangleHull> hull = detail::quickhull(points);
        if (!hull) continue;  // declined: qhull takes it (its answer is compared below)
        ++solved;
        expect_hull_of(points, *hull, 1e-10 * scale_of(points), name);
        std::set<std::uint32_t> corners;
        for (const auto& t : hull->triangles) corners.insert(t.begin(), t.end());
        EXPECT_EQ(std::vector<std::uint32_t>(corners.begin(), corners.end()), hull->vertices) << name;
    }
    // Declining is for rounding trouble, not for whole families: here every solid set is solved (the
    // others are single spheres and capsules of the random scenes: one or two centres).
    EXPECT_EQ(solved, solids);
}

TEST(Quickhull, SameSummaryAsQhull) {
    for (const auto& [name, points] : solid_sets()) {
        const std::vector<Sphere> spheres = as_spheres(points);
        const detail::HullSummary ours = detail::summarize_hull(spheres);
        const detail::HullSummary reference = detail::summarize_hull(spheres, detail::HullMethod::qhull);
        ASSERT_EQ(ours.is_solid, reference.is_solid) << name;
        if (!reference.is_solid) continue;  // a single sphere or capsule: one or two centres
        // Both drop points within rounding of a face; these sets have none that close but off it.
        EXPECT_EQ(ours.vertices.size(), reference.vertices.size()) << name;
        std::vector<std::uint32_t> sorted = reference.vertices;
        std::sort(sorted.begin(), sorted.end());
        EXPECT_EQ(ours.vertices, sorted) << name;
        const double size = reference.covariance.norm();
        EXPECT_LE((ours.covariance - reference.covariance).norm(), 1e-9 * size) << name;
        // Every normal of ours is one of qhull's (a flat face may be split into triangles differently, and
        // which of its equal-area triangles comes first may differ, so the lists are compared as sets).
        for (const Vec3& n : ours.face_normals) {
            double best = -1.0;
            for (const Vec3& m : reference.face_normals) best = std::max(best, n.dot(m));
            if (ours.face_normals.size() < detail::max_face_normals) {
                EXPECT_GT(best, 1.0 - 1e-9) << name;
            }
        }
        if (ours.face_normals.size() < detail::max_face_normals) {
            EXPECT_EQ(ours.face_normals.size(), reference.face_normals.size()) << name;
        }
    }
}

TEST(Quickhull, DeclinesWhatSpansNoSolid) {
    SplitMix64 rng(99);
    std::vector<Vec3> flat, line, same;
    const Mat3 turn = rng.rotation();
    for (int i = 0; i < 30; ++i) {
        flat.push_back(turn * Vec3(rng.uniform(-1, 1), rng.uniform(-1, 1), 0.0));
        line.push_back(turn * Vec3(rng.uniform(-1, 1), 0.0, 0.0));
        same.emplace_back(0.5, 0.5, 0.5);
    }
    EXPECT_FALSE(detail::quickhull(flat).has_value());
    EXPECT_FALSE(detail::quickhull(line).has_value());
    EXPECT_FALSE(detail::quickhull(same).has_value());
    EXPECT_FALSE(detail::quickhull(std::vector<Vec3>(flat.begin(), flat.begin() + 3)).has_value());
    // And summarize_hull then falls back to every centre, as it did with qhull alone.
    const detail::HullSummary summary = detail::summarize_hull(as_spheres(flat));
    EXPECT_FALSE(summary.is_solid);
    EXPECT_EQ(summary.vertices.size(), flat.size());
}

/// Points in a random plane (or on a line, or one point), each pushed off it by `thickness` times the set's
/// size in a random direction: `thickness` 0 leaves only the rounding of the rotation.
std::vector<Vec3> nearly_flat(SplitMix64& rng, int dimension, double thickness, std::size_t count) {
    const Mat3 turn = rng.rotation();
    const Vec3 offset(rng.uniform(-5, 5), rng.uniform(-5, 5), rng.uniform(-5, 5));
    std::vector<Vec3> points;
    for (std::size_t i = 0; i < count; ++i) {
        const Vec3 in_span(dimension >= 1 ? rng.uniform(-1, 1) : 0.0, dimension >= 2 ? rng.uniform(-1, 1) : 0.0, 0.0);
        const Vec3 off(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
        points.push_back(offset + turn * in_span + thickness * off);
    }
    return points;
}

// summarize_hull skips qhull for the sets the quickhull refuses as flat within rounding, so the flag must never be
// set on a set qhull would find a solid in. Oracle: qhull itself (HullMethod::qhull), on points and lines and planes
// whose thickness runs from exact through rounding to well above it; and the flag must be clear where the points
// are thin but measurably solid, where qhull still has the last word.
TEST(Quickhull, FlatWithinRoundingOnlyWhereQhullFindsNoSolidEither) {
    SplitMix64 rng(2026);
    int flagged = 0, left_to_qhull = 0;
    for (int dimension = 0; dimension <= 2; ++dimension)
        for (const double thickness : {0.0, 1e-17, 1e-16, 1e-15, 1e-14, 1e-13, 1e-12, 1e-9})
            for (int trial = 0; trial < 20; ++trial) {
                const std::vector<Vec3> raw = nearly_flat(rng, dimension, thickness, 4 + rng.below(40));
                // As summarize_hull passes them: centred.
                Vec3 mean = Vec3::Zero();
                for (const Vec3& p : raw) mean += p;
                mean /= static_cast<double>(raw.size());
                std::vector<Vec3> points;
                for (const Vec3& p : raw) points.push_back(p - mean);
                bool flat = false;
                const std::optional<TriangleHull> hull = detail::quickhull(points, &flat);
                if (hull) {
                    EXPECT_FALSE(flat);
                    continue;
                }
                const bool qhull_solid = detail::summarize_hull(as_spheres(points), detail::HullMethod::qhull).is_solid;
                if (flat) {
                    ++flagged;
                    EXPECT_FALSE(qhull_solid) << "dimension " << dimension << ", thickness " << thickness;
                } else {
                    ++left_to_qhull;
                }
            }
    // Both kinds of refusal occur, so the test tells them apart.
    EXPECT_GT(flagged, 100);
    EXPECT_GT(left_to_qhull, 10);

    // Exactly flat sets are flagged, and summarize_hull still falls back to every centre.
    std::vector<Vec3> plane = nearly_flat(rng, 2, 0.0, 30);
    for (Vec3& p : plane) p.z() = 0.25;
    bool flat = false;
    EXPECT_FALSE(detail::quickhull(plane, &flat).has_value());
    EXPECT_TRUE(flat);
    const detail::HullSummary summary = detail::summarize_hull(as_spheres(plane));
    EXPECT_FALSE(summary.is_solid);
    EXPECT_EQ(summary.vertices.size(), plane.size());
}

/// The points fuzz_collide found crashing the hull (a neighbour left unlinked): a box 2e-9 wide beside one point
/// 1.4 away, as summarize_hull centres them. Declining is allowed; a hull must be one.
TEST(Quickhull, TinyBoxBesideAFarPoint) {
    const std::vector<Vec3> points{
        {-0x1.c71c71c71c71cp-5, 0x1.638e38e38e38ep+0, -0x1.5555555555558p-2},
        {0x1.c71c6d7b9978p-8, -0x1.638e3905ea50bp-3, 0x1.555554cbe4f4p-5},
        {0x1.c71c76129f6ep-8, -0x1.638e3905ea50bp-3, 0x1.555554cbe4f4p-5},
        {0x1.c71c6d7b9978p-8, -0x1.638e38c132211p-3, 0x1.555554cbe4f4p-5},
        {0x1.c71c76129f6ep-8, -0x1.638e38c132211p-3, 0x1.555554cbe4f4p-5},
        {0x1.c71c6d7b9978p-8, -0x1.638e3905ea50bp-3, 0x1.555555dec5b4p-5},
        {0x1.c71c76129f6ep-8, -0x1.638e3905ea50bp-3, 0x1.555555dec5b4p-5},
        {0x1.c71c6d7b9978p-8, -0x1.638e38c132211p-3, 0x1.555555dec5b4p-5},
        {0x1.c71c76129f6ep-8, -0x1.638e38c132211p-3, 0x1.555555dec5b4p-5},
    };
    if (const std::optional<TriangleHull> hull = detail::quickhull(points)) {
        expect_hull_of(points, *hull, 1e-10 * scale_of(points), "tiny box beside a far point");
    }
}

/// The same family at random: tiny boxes (1e-13 to 1e-6 wide, turned at random) beside a few far points, the
/// way a bolt's generating spheres sit beside a hull's. Each answer is a hull or nothing, never a crash.
TEST(Quickhull, TinyClustersBesideFarPoints) {
    SplitMix64 rng(2026);
    int solved = 0;
    for (int trial = 0; trial < 3000; ++trial) {
        const Mat3 turn = rng.rotation();
        const double size = std::pow(10.0, rng.uniform(-13.0, -6.0));
        const Vec3 centre(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
        std::vector<Vec3> points;
        for (int corner = 0; corner < 8; ++corner) {
            const Vec3 offset((corner & 1) - 0.5, ((corner >> 1) & 1) - 0.5, ((corner >> 2) & 1) - 0.5);
            points.push_back(centre + size * (turn * offset));
        }
        const int far_points = 1 + static_cast<int>(rng.uniform(0.0, 3.0));
        for (int i = 0; i < far_points; ++i) points.emplace_back(rng.uniform(-2, 2), rng.uniform(-2, 2), rng.uniform(-2, 2));
        solved += hull_checked_if_solved(points, "trial " + std::to_string(trial)) ? 1 : 0;
    }
    RecordProperty("solved", solved);
}

/// Nearly flat and nearly straight sets at random (thickness 1e-14 to 1e-4 of their extent, turned at random),
/// with repeated points: rounding decides most of their faces. Each answer is a hull or nothing.
TEST(Quickhull, NearlyFlatAndNearlyStraightSets) {
    SplitMix64 rng(31);
    int solved = 0;
    for (int trial = 0; trial < 2000; ++trial) {
        const Mat3 turn = rng.rotation();
        const double thin = std::pow(10.0, rng.uniform(-14.0, -4.0));
        const bool straight = trial % 2 == 1;
        const int count = 4 + static_cast<int>(rng.uniform(0.0, 40.0));
        std::vector<Vec3> points;
        for (int i = 0; i < count; ++i) {
            const Vec3 local(rng.uniform(-1, 1), straight ? thin * rng.uniform(-1, 1) : rng.uniform(-1, 1),
                             thin * rng.uniform(-1, 1));
            points.push_back(turn * local);
            if (i % 7 == 3) points.push_back(points.back());  // a repeated point
        }
        solved += hull_checked_if_solved(points, "trial " + std::to_string(trial)) ? 1 : 0;
    }
    RecordProperty("solved", solved);
}

TEST(Quickhull, RepeatedAndInteriorPointsAreNoVertices) {
    // A cube's corners, each three times, plus points inside and on its faces: eight vertices.
    std::vector<Vec3> points;
    SplitMix64 rng(5);
    for (int copy = 0; copy < 3; ++copy)
        for (int corner = 0; corner < 8; ++corner)
            points.emplace_back(corner & 1 ? 1.0 : -1.0, corner & 2 ? 1.0 : -1.0, corner & 4 ? 1.0 : -1.0);
    for (int i = 0; i < 40; ++i) {
        Vec3 p(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
        if (i % 2 == 0) p[static_cast<Eigen::Index>(i % 3)] = 1.0;  // on a face
        points.push_back(p);
    }
    const std::optional<TriangleHull> hull = detail::quickhull(points);
    ASSERT_TRUE(hull.has_value());
    EXPECT_EQ(hull->vertices.size(), 8u);
    EXPECT_EQ(hull->triangles.size(), 12u);
    for (std::uint32_t v : hull->vertices) EXPECT_EQ(points[v].cwiseAbs(), Vec3::Ones());
    expect_hull_of(points, *hull, 1e-12, "cube");
}

/// How far `q` lies outside the convex polygon `corners` (either orientation; repeated and collinear corners
/// allowed): the largest distance beyond an edge's line, so 0 on the boundary and negative inside.
double boundary_distance(std::vector<Eigen::Vector2d> corners, const Eigen::Vector2d& q) {
    double area = 0.0;
    for (std::size_t i = 0; i < corners.size(); ++i) {
        const Eigen::Vector2d& a = corners[i];
        const Eigen::Vector2d& b = corners[(i + 1) % corners.size()];
        area += a.x() * b.y() - a.y() * b.x();
    }
    if (area < 0.0) std::reverse(corners.begin(), corners.end());
    double outside = -std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < corners.size(); ++i) {
        const Eigen::Vector2d edge = corners[(i + 1) % corners.size()] - corners[i];
        if (!(edge.norm() > 0.0)) continue;
        outside = std::max(outside, Eigen::Vector2d(edge.y(), -edge.x()).normalized().dot(q - corners[i]));
    }
    return outside;
}

TEST(HullOutline, SamePolygonAsTheSortedHullOfTheProjection) {
    // Directions: random ones, the world axes and every face normal (faces parallel to the direction are
    // then exactly or nearly perpendicular to it: the case rounding can make ambiguous).
    SplitMix64 rng(77);
    int outlines = 0, attempts = 0;
    for (const auto& [name, points] : solid_sets()) {
        const std::vector<Sphere> spheres = as_spheres(points);
        const detail::HullSummary hull = detail::summarize_hull(spheres);
        if (!hull.is_solid) continue;
        ASSERT_FALSE(hull.surface.empty()) << name;
        std::vector<Vec3> directions{Vec3::UnitX(), Vec3::UnitY(), Vec3::UnitZ()};
        for (int i = 0; i < 5; ++i) directions.push_back(rng.rotation().col(0));
        for (const Vec3& n : hull.face_normals) directions.push_back(n);
        detail::OutlineScratch scratch;
        const std::vector<std::uint32_t>& outline = scratch.outline;
        for (const Vec3& direction : directions) {
            ++attempts;
            if (!detail::outline_along(hull.surface, direction, scratch)) continue;
            ++outlines;
            const Mat3 basis = detail::frame_from_axis(direction);
            const auto project = [&](std::uint32_t input) {
                return Eigen::Vector2d(points[input].dot(basis.col(1)), points[input].dot(basis.col(2)));
            };
            std::vector<Eigen::Vector2d> projected, reference;
            for (const Vec3& p : points) projected.emplace_back(p.dot(basis.col(1)), p.dot(basis.col(2)));
            detail::hull_2d(projected, reference);
            std::vector<Eigen::Vector2d> loop;
            for (std::uint32_t slot : outline) loop.push_back(project(hull.vertices[slot]));
            const double slack = 1e-9 * scale_of(points);
            // The same convex polygon: every corner of each lies on the other's boundary.
            for (const Eigen::Vector2d& corner : reference) {
                EXPECT_LE(std::abs(boundary_distance(loop, corner)), slack) << name << ": a corner off the outline";
            }
            for (const Eigen::Vector2d& q : loop) {
                EXPECT_LE(std::abs(boundary_distance(reference, q)), slack) << name << ": an outline point off the hull";
            }
        }
    }
    // Declining is for rounding ambiguity only, which none of these sets and directions has.
    EXPECT_EQ(outlines, attempts) << outlines << " of " << attempts;
}

}  // namespace
}  // namespace hbvh
