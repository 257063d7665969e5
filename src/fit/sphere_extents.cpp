// SPDX-License-Identifier: MIT
#include "sphere_extents.hpp"

#include <algorithm>
#include <cmath>

#include "../simd/wide_clones.hpp"

namespace hbvh::detail {
namespace {

/// Four doubles: a point's x, y, z and a lane that is computed and ignored, or one coordinate of four spheres.
/// GCC's vector extension, so that the AVX2 copy works on one register where the plain copy works on two.
typedef double Lanes __attribute__((vector_size(32)));

}  // namespace

HBVH_WIDE_CLONES void extend_extents(std::span<const Sphere> spheres, const Mat3& frame, SphereExtents& extents) {
    // Row k of the frame holds what coordinate k of a centre contributes to each axis.
    const Lanes along_x{frame(0, 0), frame(0, 1), frame(0, 2), 0.0};
    const Lanes along_y{frame(1, 0), frame(1, 1), frame(1, 2), 0.0};
    const Lanes along_z{frame(2, 0), frame(2, 1), frame(2, 2), 0.0};
    Lanes low{extents.low.x(), extents.low.y(), extents.low.z(), 0.0};
    Lanes high{extents.high.x(), extents.high.y(), extents.high.z(), 0.0};
    for (const Sphere& s : spheres) {
        const double x = s.center.x(), y = s.center.y(), z = s.center.z(), r = s.radius;
        const Lanes local = (Lanes{x, x, x, x} * along_x + Lanes{y, y, y, y} * along_y) + Lanes{z, z, z, z} * along_z;
        const Lanes radius{r, r, r, r};
        const Lanes below = local - radius;
        const Lanes above = local + radius;
        low = below < low ? below : low;
        high = above > high ? above : high;
    }
    extents.low = Vec3(low[0], low[1], low[2]);
    extents.high = Vec3(high[0], high[1], high[2]);
}

HBVH_WIDE_CLONES void extend_half_extents(std::span<const Sphere> spheres, const Mat3& frame, const Vec3& center,
                                          Vec3& half_extents) {
    const Lanes along_x{frame(0, 0), frame(0, 1), frame(0, 2), 0.0};
    const Lanes along_y{frame(1, 0), frame(1, 1), frame(1, 2), 0.0};
    const Lanes along_z{frame(2, 0), frame(2, 1), frame(2, 2), 0.0};
    Lanes half{half_extents.x(), half_extents.y(), half_extents.z(), 0.0};
    for (const Sphere& s : spheres) {
        const double x = s.center.x() - center.x(), y = s.center.y() - center.y(), z = s.center.z() - center.z();
        const double r = s.radius;
        const Lanes local = (Lanes{x, x, x, x} * along_x + Lanes{y, y, y, y} * along_y) + Lanes{z, z, z, z} * along_z;
        const Lanes reach = (local < 0.0 ? -local : local) + Lanes{r, r, r, r};
        half = reach > half ? reach : half;
    }
    half_extents = Vec3(half[0], half[1], half[2]);
}

HBVH_WIDE_CLONES LineReach line_reach(std::span<const Sphere> spheres, const Vec3& origin, const Vec3& axis) {
    // Four spheres at a time, one register per coordinate, so that every lane is one sphere and does the scalar
    // tail's operations in its order. (The registers are filled element by element: a shuffle would be GCC's
    // __builtin_shuffle or Clang's __builtin_shufflevector, and the fuzz targets build this file with Clang.)
    const double ox = origin.x(), oy = origin.y(), oz = origin.z();
    const double ax = axis.x(), ay = axis.y(), az = axis.z();
    const std::size_t blocks = spheres.size() / 4;
    Lanes radius{0.0, 0.0, 0.0, 0.0};
    constexpr double infinity = std::numeric_limits<double>::infinity();
    Lanes t_min{infinity, infinity, infinity, infinity};
    Lanes t_max = -t_min;
    for (std::size_t b = 0; b < blocks; ++b) {
        const Sphere& s0 = spheres[4 * b];
        const Sphere& s1 = spheres[4 * b + 1];
        const Sphere& s2 = spheres[4 * b + 2];
        const Sphere& s3 = spheres[4 * b + 3];
        const Lanes x{s0.center.x(), s1.center.x(), s2.center.x(), s3.center.x()};
        const Lanes y{s0.center.y(), s1.center.y(), s2.center.y(), s3.center.y()};
        const Lanes z{s0.center.z(), s1.center.z(), s2.center.z(), s3.center.z()};
        const Lanes r{s0.radius, s1.radius, s2.radius, s3.radius};
        const Lanes dx = x - ox, dy = y - oy, dz = z - oz;
        const Lanes t = (dx * ax + dy * ay) + dz * az;
        const Lanes ex = dx - t * ax, ey = dy - t * ay, ez = dz - t * az;
        const Lanes squared = (ex * ex + ey * ey) + ez * ez;
        Lanes distance;
        for (int k = 0; k < 4; ++k) distance[k] = std::sqrt(squared[k]);
        const Lanes reach = distance + r;
        radius = reach > radius ? reach : radius;
        t_min = t < t_min ? t : t_min;
        t_max = t > t_max ? t : t_max;
    }
    LineReach out;
    for (int k = 0; k < 4; ++k) {
        out.radius = std::max(out.radius, radius[k]);
        out.t_min = std::min(out.t_min, t_min[k]);
        out.t_max = std::max(out.t_max, t_max[k]);
    }
    for (const Sphere& s : spheres.subspan(4 * blocks)) {
        const double dx = s.center.x() - ox, dy = s.center.y() - oy, dz = s.center.z() - oz;
        const double t = (dx * ax + dy * ay) + dz * az;
        const double ex = dx - t * ax, ey = dy - t * ay, ez = dz - t * az;
        out.radius = std::max(out.radius, std::sqrt((ex * ex + ey * ey) + ez * ez) + s.radius);
        out.t_min = std::min(out.t_min, t);
        out.t_max = std::max(out.t_max, t);
    }
    return out;
}

}  // namespace hbvh::detail
