// SPDX-License-Identifier: MIT
// Shared helpers of the importer tests: comparing bounding volumes and locating test data.
#pragma once

#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "hbvh/geometry/bounding_volume.hpp"

namespace hbvh::test {

inline std::filesystem::path test_data_dir() { return std::filesystem::path(HBVH_SOURCE_DIR) / "tests/io/data"; }
inline std::filesystem::path shared_models_dir() { return std::filesystem::path(HBVH_SHARED_DIR) / "data/models"; }
inline std::filesystem::path shared_meshes_dir() { return std::filesystem::path(HBVH_SHARED_DIR) / "data/meshes"; }

/// Empty when `a` and `b` are the same kind and agree to `tolerance` in every field, else what differs.
inline std::string compare_volumes(const BoundingVolume& a, const BoundingVolume& b, double tolerance) {
    if (a.index() != b.index())
        return "kind " + std::string(to_string(type_of(a))) + " vs " + std::string(to_string(type_of(b)));
    auto far = [&](const auto& x, const auto& y) { return (x - y).cwiseAbs().maxCoeff() > tolerance; };
    if (const auto* s = std::get_if<Sphere>(&a)) {
        const auto& t = std::get<Sphere>(b);
        if (far(s->center, t.center) || std::abs(s->radius - t.radius) > tolerance) return "sphere differs";
    } else if (const auto* c = std::get_if<Capsule>(&a)) {
        const auto& d = std::get<Capsule>(b);
        // A capsule is symmetric: its two end points may come in either order.
        const bool same_ends = (!far(c->p0, d.p0) && !far(c->p1, d.p1)) || (!far(c->p0, d.p1) && !far(c->p1, d.p0));
        if (!same_ends || std::abs(c->radius - d.radius) > tolerance) return "capsule differs";
    } else if (const auto* o = std::get_if<Obb>(&a)) {
        const auto& p = std::get<Obb>(b);
        if (far(o->center, p.center)) return "obb centre differs";
        // The same box can be written with its axes permuted or negated when half extents are equal (a fromto
        // box has a square cross-section), so match every axis of one to a parallel axis of equal extent.
        for (int i = 0; i < 3; ++i) {
            bool matched = false;
            for (int j = 0; j < 3 && !matched; ++j)
                matched = std::abs(o->half_extents[i] - p.half_extents[j]) <= tolerance &&
                          (!far(o->rotation.col(i), p.rotation.col(j)) || !far(o->rotation.col(i), -p.rotation.col(j)));
            if (!matched) return "obb axes or half extents differ";
        }
    } else {
        const auto& e = std::get<Aabb>(a);
        const auto& f = std::get<Aabb>(b);
        if (far(e.min, f.min) || far(e.max, f.max)) return "aabb differs";
    }
    return {};
}

/// A printable description of a volume for failure messages.
inline std::string describe(const BoundingVolume& bv) {
    std::string out(to_string(type_of(bv)));
    const Aabb box = world_aabb(bv);
    auto vec = [](const Vec3& v) {
        return "(" + std::to_string(v.x()) + "," + std::to_string(v.y()) + "," + std::to_string(v.z()) + ")";
    };
    return out + " aabb " + vec(box.min) + ".." + vec(box.max);
}

}  // namespace hbvh::test
