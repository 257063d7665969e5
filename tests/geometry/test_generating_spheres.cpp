// SPDX-License-Identifier: MIT
// generating_sphere_count against what append_generating_spheres actually appends, for every kind.
#include <gtest/gtest.h>

#include <vector>

#include "hbvh/geometry/bounding_volume.hpp"

namespace hbvh {
namespace {

TEST(GeneratingSpheres, CountIsWhatIsAppended) {
    const std::vector<BoundingVolume> volumes{
        Aabb{Vec3(-1, -2, -3), Vec3(1, 2, 3)},
        Obb{Vec3(1, 0, 0), Mat3::Identity(), Vec3(0.5, 1, 2)},
        Sphere{Vec3(0, 1, 0), 0.5},
        Capsule{Vec3(0, 0, 0), Vec3(0, 0, 2), 0.25},
    };
    std::vector<Sphere> appended{Sphere{Vec3::Zero(), 1.0}};  // appending keeps what was there
    for (const BoundingVolume& bv : volumes) {
        const std::size_t before = appended.size();
        append_generating_spheres(bv, appended);
        EXPECT_EQ(generating_sphere_count(bv), appended.size() - before) << bv.index();
        EXPECT_EQ(generating_sphere_count(bv), generating_spheres(bv).size()) << bv.index();
    }
}

}  // namespace
}  // namespace hbvh
