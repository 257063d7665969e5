// SPDX-License-Identifier: MIT
#include "hbvh/geometry/bounding_volume.hpp"

#include <type_traits>

namespace hbvh {
namespace {
constexpr std::array<std::string_view, bv_type_count> type_names{"aabb", "obb", "sphere", "capsule"};
}  // namespace

std::string_view to_string(BvType type) { return type_names[static_cast<std::size_t>(type)]; }

std::optional<BvType> parse_bv_type(std::string_view name) {
    for (BvType type : all_bv_types)
        if (to_string(type) == name) return type;
    return std::nullopt;
}

double volume(const BoundingVolume& bv) {
    return std::visit([](const auto& v) { return v.volume(); }, bv);
}

BoundingVolume transformed(const BoundingVolume& bv, const RigidTransform& t) {
    return std::visit(Overloaded{
                          [&](const Aabb& box) -> BoundingVolume { return Obb::from_aabb(box).transformed(t); },
                          [&](const auto& v) -> BoundingVolume { return v.transformed(t); },
                      },
                      bv);
}

bool contains(const BoundingVolume& bv, const Sphere& s, double tolerance) {
    return std::visit([&](const auto& v) { return v.contains(s, tolerance); }, bv);
}

double protrusion(const BoundingVolume& bv, const Sphere& s) {
    return std::visit(Overloaded{
                          [&](const Aabb& box) {
                              const Vec3 below = box.min - s.center, above = s.center - box.max;
                              return below.cwiseMax(above).maxCoeff() + s.radius;
                          },
                          [&](const Obb& box) {
                              const Vec3 local = box.rotation.transpose() * (s.center - box.center);
                              return (local.cwiseAbs() - box.half_extents).maxCoeff() + s.radius;
                          },
                          [&](const Sphere& sphere) { return (s.center - sphere.center).norm() + s.radius - sphere.radius; },
                          [&](const Capsule& capsule) {
                              return (s.center - capsule.closest_axis_point(s.center)).norm() + s.radius - capsule.radius;
                          },
                      },
                      bv);
}

Aabb world_aabb(const BoundingVolume& bv) {
    return std::visit(Overloaded{
                          [](const Aabb& box) { return box; },
                          [](const Obb& box) {
                              // Projected half-width on world axis i is sum_j |R_ij| * e_j.
                              const Vec3 r = box.rotation.cwiseAbs() * box.half_extents;
                              return Aabb{box.center - r, box.center + r};
                          },
                          [](const Sphere& s) {
                              const Vec3 r = Vec3::Constant(s.radius);
                              return Aabb{s.center - r, s.center + r};
                          },
                          [](const Capsule& c) {
                              const Vec3 r = Vec3::Constant(c.radius);
                              return Aabb{c.p0.cwiseMin(c.p1) - r, c.p0.cwiseMax(c.p1) + r};
                          },
                      },
                      bv);
}

double size_scale(const BoundingVolume& bv) {
    const Aabb box = world_aabb(bv);
    return 0.5 * (box.max - box.min).norm();
}

void append_generating_spheres(const BoundingVolume& bv, std::vector<Sphere>& out) {
    std::visit(Overloaded{
                   [&](const Aabb& box) {
                       for (int i = 0; i < 8; ++i)
                           out.push_back({Vec3(i & 1 ? box.max.x() : box.min.x(), i & 2 ? box.max.y() : box.min.y(),
                                               i & 4 ? box.max.z() : box.min.z()),
                                          0.0});
                   },
                   [&](const Obb& box) {
                       for (int i = 0; i < 8; ++i) out.push_back({box.corner(i), 0.0});
                   },
                   [&](const Sphere& s) { out.push_back(s); },
                   [&](const Capsule& c) {
                       out.push_back({c.p0, c.radius});
                       out.push_back({c.p1, c.radius});
                   },
               },
               bv);
}

std::vector<Sphere> generating_spheres(const BoundingVolume& bv) {
    std::vector<Sphere> out;
    append_generating_spheres(bv, out);
    return out;
}

}  // namespace hbvh
