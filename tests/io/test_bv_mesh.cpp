// SPDX-License-Identifier: MIT
// triangulate(): vertices on the surface, exact normals, outward winding, closed topology, exact bounds.
#include <gtest/gtest.h>

#include <map>
#include <utility>

#include "hbvh/io/bv_mesh.hpp"
#include "hbvh/scene/generate.hpp"

namespace hbvh {
namespace {

/// Distance from `point` to the boundary surface of `bv` (zero on the surface).
double surface_distance(const BoundingVolume& bv, const Vec3& point) {
    const auto box_distance = [&](const Obb& box) {
        const Vec3 local = (box.rotation.transpose() * (point - box.center)).cwiseAbs();
        const Vec3 outside = (local - box.half_extents).cwiseMax(Vec3::Zero());
        if (outside.squaredNorm() > 0.0) return outside.norm();
        return (box.half_extents - local).minCoeff();
    };
    if (const auto* box = std::get_if<Aabb>(&bv)) return box_distance(Obb::from_aabb(*box));
    if (const auto* box = std::get_if<Obb>(&bv)) return box_distance(*box);
    if (const auto* sphere = std::get_if<Sphere>(&bv)) return std::abs((point - sphere->center).norm() - sphere->radius);
    const auto& capsule = std::get<Capsule>(bv);
    return std::abs((point - capsule.closest_axis_point(point)).norm() - capsule.radius);
}

/// A spread of every kind: axis-aligned and rotated, tilted and axis-parallel capsules, degenerate ones.
std::vector<BoundingVolume> sample_volumes() {
    SplitMix64 random(42);
    std::vector<BoundingVolume> out{
        Aabb{Vec3(-1, 2, 3), Vec3(4, 2.5, 3.25)},
        Aabb{Vec3(1, 1, 1), Vec3(1, 2, 3)},  // flat
        Obb{Vec3(0, 0, 0), Mat3::Identity(), Vec3(1, 2, 3)},
        Sphere{Vec3(1, -2, 0.5), 0.75},
        Sphere{Vec3(100, 200, 300), 1e-3},
        Capsule{Vec3(0, 0, 0), Vec3(0, 0, 2), 0.5},         // along z
        Capsule{Vec3(0, 0, 0), Vec3(3, 0, 0), 0.25},        // along x
        Capsule{Vec3(1, 1, 1), Vec3(1, 1, 1), 0.5},         // a sphere in disguise
        Capsule{Vec3(0, 0, 0), Vec3(1e-3, 0, 0), 1.0},      // nearly a sphere
        Capsule{Vec3(0, 0, 0), Vec3(-1, 1, 0), 0.7},        // perpendicular to z, tilted in xy
    };
    for (int i = 0; i < 12; ++i) {
        const Vec3 centre(random.uniform(-5, 5), random.uniform(-5, 5), random.uniform(-5, 5));
        out.push_back(Obb{centre, random.rotation(),
                          Vec3(random.uniform(0.1, 2), random.uniform(0.1, 2), random.uniform(0.1, 2))});
        const Vec3 axis = random.rotation().col(0) * random.uniform(0.1, 4);
        out.push_back(Capsule{centre, centre + axis, random.uniform(0.05, 1.5)});
        out.push_back(Sphere{centre, random.uniform(0.05, 3)});
    }
    return out;
}

TEST(Triangulate, VerticesLieOnTheSurface) {
    for (const BoundingVolume& bv : sample_volumes()) {
        const TriangleMesh mesh = triangulate(bv);
        ASSERT_FALSE(mesh.positions.empty());
        const double tolerance = 1e-9 * size_scale(bv);
        for (const Vec3& p : mesh.positions)
            ASSERT_LT(surface_distance(bv, p), tolerance) << to_string(type_of(bv)) << " vertex " << p.transpose();
    }
}

TEST(Triangulate, BoundingBoxIsTheWorldAabb) {
    for (const BoundingVolume& bv : sample_volumes()) {
        const TriangleMesh mesh = triangulate(bv, {8, 4});  // coarse: the extremes must still be hit
        Aabb bounds = Aabb::empty();
        for (const Vec3& p : mesh.positions) bounds = bounds.merged({p, p});
        const Aabb expected = world_aabb(bv);
        const double tolerance = 1e-9 * size_scale(bv);
        EXPECT_LT((bounds.min - expected.min).cwiseAbs().maxCoeff(), tolerance) << to_string(type_of(bv));
        EXPECT_LT((bounds.max - expected.max).cwiseAbs().maxCoeff(), tolerance) << to_string(type_of(bv));
    }
}

TEST(Triangulate, NormalsAreUnitAndOutward) {
    for (const BoundingVolume& bv : sample_volumes()) {
        const TriangleMesh mesh = triangulate(bv);
        ASSERT_EQ(mesh.normals.size(), mesh.positions.size());
        const double step = 1e-6 * size_scale(bv);
        for (std::size_t i = 0; i < mesh.normals.size(); ++i) {
            ASSERT_NEAR(mesh.normals[i].norm(), 1.0, 1e-12);
            // Outward: a small step along the normal leaves the solid, a step against it enters.
            const Vec3& p = mesh.positions[i];
            EXPECT_FALSE(contains(bv, Sphere{p + step * mesh.normals[i], 0.0}));
            if (!std::holds_alternative<Aabb>(bv) && !std::holds_alternative<Obb>(bv)) {
                // Curved kinds: the normal is the exact gradient direction.
                const Vec3 axis_point = std::holds_alternative<Sphere>(bv)
                                            ? std::get<Sphere>(bv).center
                                            : std::get<Capsule>(bv).closest_axis_point(p);
                const Vec3 radial = p - axis_point;
                if (radial.norm() > 1e-9) {
                    EXPECT_LT((radial.normalized() - mesh.normals[i]).norm(), 1e-9);
                }
            }
        }
    }
}

TEST(Triangulate, TrianglesWindCounterClockwiseFromOutside) {
    for (const BoundingVolume& bv : sample_volumes()) {
        const TriangleMesh mesh = triangulate(bv);
        ASSERT_EQ(mesh.indices.size() % 3, 0u);
        for (std::size_t t = 0; t < mesh.indices.size(); t += 3) {
            const std::uint32_t a = mesh.indices[t], b = mesh.indices[t + 1], c = mesh.indices[t + 2];
            ASSERT_LT(std::max({a, b, c}), mesh.positions.size());
            const Vec3 face = (mesh.positions[b] - mesh.positions[a]).cross(mesh.positions[c] - mesh.positions[a]);
            const Vec3 normal = mesh.normals[a] + mesh.normals[b] + mesh.normals[c];
            if (face.norm() > 1e-12 * size_scale(bv) * size_scale(bv)) {
                EXPECT_GT(face.dot(normal), 0.0) << to_string(type_of(bv)) << " triangle " << t / 3 << " of " << mesh.triangle_count() << " a " << mesh.positions[a].transpose() << " b " << mesh.positions[b].transpose() << " c " << mesh.positions[c].transpose();
            }
        }
    }
}

TEST(Triangulate, CurvedSurfacesAreClosed) {
    // Each directed edge once and its reverse once: no holes, no flipped triangles.
    for (const BoundingVolume& bv : sample_volumes()) {
        if (std::holds_alternative<Aabb>(bv) || std::holds_alternative<Obb>(bv)) continue;
        const TriangleMesh mesh = triangulate(bv, {12, 6});
        std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
        for (std::size_t t = 0; t < mesh.indices.size(); t += 3)
            for (int k = 0; k < 3; ++k) ++edges[{mesh.indices[t + k], mesh.indices[t + (k + 1) % 3]}];
        for (const auto& [edge, count] : edges) {
            EXPECT_EQ(count, 1);
            EXPECT_EQ(edges.count({edge.second, edge.first}), 1u);
        }
    }
}

TEST(Triangulate, BoxLayoutIsFourVerticesPerFace) {
    const TriangleMesh mesh = triangulate(Aabb{Vec3(0, 0, 0), Vec3(1, 2, 3)});
    ASSERT_EQ(mesh.positions.size(), 24u);
    ASSERT_EQ(mesh.indices.size(), 36u);
    const Vec3 expected_normals[] = {-Vec3::UnitX(), Vec3::UnitX(), -Vec3::UnitY(),
                                     Vec3::UnitY(),  -Vec3::UnitZ(), Vec3::UnitZ()};
    for (std::size_t face = 0; face < 6; ++face)
        for (std::size_t k = 0; k < 4; ++k) EXPECT_EQ(mesh.normals[4 * face + k], expected_normals[face]);
}

TEST(Triangulate, DetailIsRoundedToKeepExtremes) {
    // 5 segments and 3 rings round up to 8 and 4: the equator and the quarter turns exist.
    const TriangleMesh mesh = triangulate(Sphere{Vec3::Zero(), 1.0}, {5, 3});
    EXPECT_EQ(mesh.positions.size(), 2u + 3u * 8u);
}

}  // namespace
}  // namespace hbvh
