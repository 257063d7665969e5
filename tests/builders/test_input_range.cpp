// SPDX-License-Identifier: MIT
// build() refuses inputs whose volumes overflow or underflow double precision, and only those.
#include <gtest/gtest.h>

#include <limits>
#include <string>
#include <vector>

#include "hbvh/builders/build.hpp"

namespace hbvh {
namespace {

/// Two spheres of radius `size` `size` apart along every axis, so the world box is about 3 x size a side.
std::vector<Primitive> two_spheres(double size) {
    return {Primitive{Sphere{Vec3::Zero(), size}, "a"}, Primitive{Sphere{Vec3::Constant(size), size}, "b"}};
}

TEST(InputRange, OrdinaryScalesAreAccepted) {
    for (double size : {1e-90, 1e-3, 1.0, 1e3, 1e90}) {
        EXPECT_TRUE(check_finite_extent(two_spheres(size)).has_value()) << size;
        EXPECT_TRUE(build(two_spheres(size), Algorithm::optimal).has_value()) << size;
    }
}

TEST(InputRange, OverflowIsRefusedWithAMessage) {
    const Status checked = check_finite_extent(two_spheres(1e120));
    ASSERT_FALSE(checked.has_value());
    EXPECT_NE(checked.error().message.find("overflow"), std::string::npos);
    // Every builder refuses, the exact ones included (optimal used to run for minutes on such input).
    for (const AlgorithmInfo& info : algorithms())
        EXPECT_FALSE(build(two_spheres(1e120), info.algorithm()).has_value()) << info.name;
}

TEST(InputRange, TheMessageNamesThePrimitivesThatSetTheWidestExtent) {
    // Fifty unit spheres and one stray far away: the message leads to the stray by index and name.
    std::vector<Primitive> primitives;
    for (int i = 0; i < 50; ++i) primitives.push_back({Sphere{Vec3(i, 0, 0), 1.0}, ""});
    primitives.insert(primitives.begin() + 31, Primitive{Sphere{Vec3(0, 1e160, -1e200), 1.0}, "stray"});
    const Status checked = check_finite_extent(primitives);
    ASSERT_FALSE(checked.has_value());
    const std::string& message = checked.error().message;
    EXPECT_NE(message.find("along z from primitive 31 ('stray') to primitive 0"), std::string::npos) << message;
    primitives[31].volume = Sphere{Vec3(0, std::numeric_limits<double>::infinity(), 0), 1.0};
    const Status infinite = check_finite_extent(primitives);
    ASSERT_FALSE(infinite.has_value());
    EXPECT_EQ(infinite.error().message,
              "primitive 31 ('stray') reaches beyond the range of double (its bounding box is not finite); scale the "
              "model down");
    // Finite numbers whose box is not: a sphere of radius 1e308 at x = 1e308 (reported as "non-finite coordinates"
    // until 2026-12-07, which its numbers are not).
    primitives[31].volume = Sphere{Vec3(1e308, 0, 0), 1e308};
    const Status beyond = check_finite_extent(primitives);
    ASSERT_FALSE(beyond.has_value());
    EXPECT_NE(beyond.error().message.find("primitive 31 ('stray') reaches beyond the range of double"), std::string::npos)
        << beyond.error().message;
}

TEST(InputRange, UnderflowIsRefusedButAFlatModelIsNot) {
    const Status checked = check_finite_extent(two_spheres(1e-120));
    ASSERT_FALSE(checked.has_value());
    EXPECT_NE(checked.error().message.find("underflow"), std::string::npos);
    // Boxes in one plane: the world box has zero height, its volume is truly zero, nothing underflows.
    const Aabb flat_a{Vec3(0, 0, 0), Vec3(1, 1, 0)};
    const Aabb flat_b{Vec3(2, 0, 0), Vec3(3, 1, 0)};
    const std::vector<Primitive> flat{Primitive{flat_a, "a"}, Primitive{flat_b, "b"}};
    EXPECT_TRUE(check_finite_extent(flat).has_value());
}

}  // namespace
}  // namespace hbvh
