// SPDX-License-Identifier: MIT
#include "sphere_extents.hpp"

#include "../simd/wide_clones.hpp"

namespace hbvh::detail {
namespace {

/// Four doubles: x, y, z and a lane that is computed and ignored. GCC's vector extension, so that the
/// AVX2 copy works on one register where the plain copy works on two.
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

}  // namespace hbvh::detail
