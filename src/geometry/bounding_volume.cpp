// SPDX-License-Identifier: MIT
#include "hbvh/geometry/bounding_volume.hpp"

#include <numbers>
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

namespace {
/// Surface area and mean width of a box with full edges `e`.
double box_area(const Vec3& e) { return 2.0 * (e.x() * e.y() + e.y() * e.z() + e.z() * e.x()); }
double box_mean_width(const Vec3& e) { return 0.5 * e.sum(); }
}  // namespace

double surface_area(const BoundingVolume& bv) {
    return std::visit(Overloaded{
                          [](const Aabb& box) { return box_area(box.max - box.min); },
                          [](const Obb& box) { return box_area(2.0 * box.half_extents); },
                          [](const Sphere& s) { return 4.0 * std::numbers::pi * s.radius * s.radius; },
                          [](const Capsule& c) {
                              return 2.0 * std::numbers::pi * c.radius * c.length() +
                                     4.0 * std::numbers::pi * c.radius * c.radius;
                          },
                      },
                      bv);
}

double mean_width(const BoundingVolume& bv) {
    // Mean width adds under Minkowski sums, and a segment of length L has mean width L/2: a capsule
    // (segment + ball) has 2r + L/2.
    return std::visit(Overloaded{
                          [](const Aabb& box) { return box_mean_width(box.max - box.min); },
                          [](const Obb& box) { return box_mean_width(2.0 * box.half_extents); },
                          [](const Sphere& s) { return 2.0 * s.radius; },
                          [](const Capsule& c) { return 2.0 * c.radius + 0.5 * c.length(); },
                      },
                      bv);
}

double self_minkowski_volume(const BoundingVolume& bv) { return 2.0 * volume(bv) + surface_area(bv) * mean_width(bv); }

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
    return std::visit([&](const auto& v) { return protrusion(v, s); }, bv);
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

std::size_t generating_sphere_count(const BoundingVolume& bv) {
    return std::visit(Overloaded{[](const Aabb&) -> std::size_t { return 8; }, [](const Obb&) -> std::size_t { return 8; },
                                 [](const Sphere&) -> std::size_t { return 1; }, [](const Capsule&) -> std::size_t { return 2; }},
                      bv);
}

std::vector<Sphere> generating_spheres(const BoundingVolume& bv) {
    std::vector<Sphere> out;
    append_generating_spheres(bv, out);
    return out;
}

}  // namespace hbvh
