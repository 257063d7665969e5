// SPDX-License-Identifier: MIT
// validate_primitives / validate_pose / from_quaternion: what the library refuses, and that build(),
// QueryTree and collide() refuse it too instead of pruning on it.
#include <array>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "hbvh/builders/build.hpp"
#include "hbvh/geometry/validation.hpp"
#include "hbvh/query/tandem_traversal.hpp"
#include "hbvh/scene/generate.hpp"

namespace hbvh {
namespace {

constexpr double nan = std::numeric_limits<double>::quiet_NaN();
constexpr double inf = std::numeric_limits<double>::infinity();

std::vector<Primitive> good_primitives() {
    return {{Aabb{Vec3(0, 0, 0), Vec3(1, 1, 1)}, "box"},
            {Sphere{Vec3(3, 0, 0), 0.5}, "ball"},
            {Capsule{Vec3(0, 3, 0), Vec3(1, 3, 0), 0.25}, "rod"},
            {Obb{Vec3(5, 5, 5), Eigen::AngleAxisd(0.3, Vec3::UnitZ()).toRotationMatrix(), Vec3(1, 2, 0.5)}, "crate"}};
}

/// The Error message of validate_primitives after replacing primitive 1 by `bad`.
std::string refusal(BoundingVolume bad) {
    std::vector<Primitive> primitives = good_primitives();
    primitives[1] = {std::move(bad), "bad one"};
    const Status status = validate_primitives(primitives);
    return status ? std::string{} : status.error().message;
}

TEST(ValidatePrimitives, AcceptsGoodAndDegenerateButUsableGeometry) {
    EXPECT_TRUE(validate_primitives(good_primitives()));
    std::vector<Primitive> degenerate{{Aabb{Vec3(0, 0, 0), Vec3(1, 0, 1)}, "flat"},
                                      {Sphere{Vec3(0, 0, 0), 0.0}, "point"},
                                      {Capsule{Vec3(1, 1, 1), Vec3(1, 1, 1), 0.5}, "ball-like capsule"}};
    EXPECT_TRUE(validate_primitives(degenerate));
}

TEST(ValidatePrimitives, NamesTheIndexNameAndProblem) {
    const std::string message = refusal(Sphere{Vec3(0, 0, 0), -0.5});
    EXPECT_NE(message.find("primitive 1 ('bad one')"), std::string::npos) << message;
    EXPECT_NE(message.find("negative"), std::string::npos) << message;
}

TEST(ValidatePrimitives, RefusesANameWithANulByte) {
    // XML and .hbvh both end a name at a NUL: saved, "a\0b" came back as "a" without a word.
    const std::vector<Primitive> primitives{{Sphere{Vec3(0, 0, 0), 1.0}, "ok"},
                                            {Sphere{Vec3(3, 0, 0), 1.0}, std::string("a\0b", 3)}};
    const Status status = validate_primitives(primitives);
    ASSERT_FALSE(status);
    EXPECT_EQ(status.error().message, "primitive 1: its name holds a NUL byte, which no hierarchy file keeps");
}

TEST(ValidatePrimitives, RefusesEveryKindOfBadNumber) {
    Mat3 shear = Mat3::Identity();
    shear(0, 1) = 1e-6;
    Mat3 mirror = Mat3::Identity();
    mirror(2, 2) = -1.0;
    const double denormal = std::numeric_limits<double>::denorm_min() * 4;
    const std::vector<std::pair<BoundingVolume, const char*>> cases{
        {Sphere{Vec3(nan, 0, 0), 1.0}, "not finite"},
        {Sphere{Vec3(0, 0, 0), nan}, "not a finite number"},
        {Sphere{Vec3(0, 0, 0), inf}, "not a finite number"},
        {Sphere{Vec3(0, 0, 0), denormal}, "subnormal"},
        {Capsule{Vec3(0, 0, 0), Vec3(1, 0, 0), -1.0}, "negative"},
        {Capsule{Vec3(0, nan, 0), Vec3(1, 0, 0), 1.0}, "not finite"},
        {Capsule{Vec3(-1e308, 0, 0), Vec3(1e308, 0, 0), 1.0}, "overflows"},
        {Aabb{Vec3(0, 0, 0), Vec3(1, -1, 1)}, "negative"},
        {Aabb{Vec3(0, 0, 0), Vec3(1, nan, 1)}, "not finite"},
        {Aabb{Vec3(0, 0, 0), Vec3(1, denormal, 1)}, "subnormal"},
        {Aabb{Vec3(-1e308, 0, 0), Vec3(1e308, 1, 1)}, "not finite"},
        {Obb{Vec3(0, 0, 0), shear, Vec3(1, 1, 1)}, "not orthonormal"},
        {Obb{Vec3(0, 0, 0), mirror, Vec3(1, 1, 1)}, "reflection"},
        {Obb{Vec3(0, 0, 0), Mat3::Identity(), Vec3(1, -2, 1)}, "negative"},
        {Obb{Vec3(0, 0, 0), Mat3::Constant(nan), Vec3(1, 1, 1)}, "not finite"},
    };
    for (const auto& [volume, expected] : cases) {
        const std::string message = refusal(volume);
        EXPECT_NE(message.find(expected), std::string::npos) << "expected '" << expected << "', got '" << message << "'";
    }
}

TEST(ValidatePose, RefusesNonRigidMotions) {
    EXPECT_TRUE(validate_pose(RigidTransform::identity()));
    EXPECT_TRUE(validate_pose(RigidTransform::from_quaternion(0.92, 0.0, 0.38, 0.0, Vec3(1e5, 0, 0))));
    RigidTransform scaled;
    scaled.rotation *= 1.001;
    EXPECT_FALSE(validate_pose(scaled));
    RigidTransform mirrored;
    mirrored.rotation(1, 1) = -1.0;
    EXPECT_FALSE(validate_pose(mirrored));
    RigidTransform nan_translation;
    nan_translation.translation.x() = nan;
    EXPECT_FALSE(validate_pose(nan_translation));
    EXPECT_FALSE(validate_pose(RigidTransform::from_quaternion(0, 0, 0, 0)));
    EXPECT_FALSE(validate_pose(RigidTransform::from_quaternion(nan, 0, 0, 1)));
    EXPECT_FALSE(validate_pose(RigidTransform::from_quaternion(std::numeric_limits<double>::infinity(), 0, 0, 1)));
    // Any finite non-zero quaternion is a rotation, also one whose length no double holds (2e308 gave NaN).
    const RigidTransform huge = RigidTransform::from_quaternion(1e308, 1e308, 1e308, 1e308);
    ASSERT_TRUE(validate_pose(huge));
    const RigidTransform one = RigidTransform::from_quaternion(1, 1, 1, 1);
    EXPECT_LT((huge.rotation - one.rotation).cwiseAbs().maxCoeff(), 1e-15);
    EXPECT_TRUE(validate_pose(RigidTransform::from_quaternion(1e-310, 0, 0, 1e-310)));
}

TEST(ValidatePose, AnyNonZeroFiniteQuaternionGivesTheRotationOfItsDirection) {
    // Components whose squares overflow or underflow (the plain norm's) were refused as "not finite".
    const std::pair<std::array<double, 4>, std::array<double, 4>> same[] = {
        {{1e-300, 1e-300, 0, 0}, {1, 1, 0, 0}},
        {{4e-320, 0, 0, 0}, {1, 0, 0, 0}},
        {{1e300, 1e300, 1e300, 1e300}, {1, 1, 1, 1}},
    };
    for (const auto& [tiny_or_huge, unit] : same) {
        const RigidTransform pose = RigidTransform::from_quaternion(tiny_or_huge[0], tiny_or_huge[1], tiny_or_huge[2], tiny_or_huge[3]);
        EXPECT_TRUE(validate_pose(pose)) << tiny_or_huge[0];
        const RigidTransform expected = RigidTransform::from_quaternion(unit[0], unit[1], unit[2], unit[3]);
        EXPECT_LT((pose.rotation - expected.rotation).cwiseAbs().maxCoeff(), 1e-15) << tiny_or_huge[0];
    }
}

TEST(ValidatePose, TheQuickCheckAgreesWithTheWordedOne) {
    // is_rigid_motion() runs on every query, validate_pose() only to word a refusal: they must never
    // disagree, also next to the tolerance, where rounding decides.
    SplitMix64 rng(17);
    for (int k = 0; k < 20000; ++k) {
        RigidTransform pose{rng.rotation(), Vec3(rng.uniform(-1e3, 1e3), 0.0, 0.0)};
        const double size = std::pow(10.0, rng.uniform(-12.0, -6.0));
        pose.rotation(static_cast<int>(rng.below(3)), static_cast<int>(rng.below(3))) += rng.uniform(-size, size);
        if (k % 7 == 0) pose.rotation.col(0) = -pose.rotation.col(0);
        EXPECT_EQ(is_rigid_motion(pose), rotation_problem(pose.rotation).empty()) << k;
    }
}

// nearest_rotation against its definition: a rounded rotation comes back a proper rotation, no further from the
// rounded matrix (Frobenius) than the rotation it was rounded from, nor than that one turned a little either way.
TEST(NearestRotation, IsARotationNoFurtherThanTheOneRoundedOrItsNeighbours) {
    SplitMix64 rng(41);
    for (int k = 0; k < 2000; ++k) {
        const Mat3 exact = rng.rotation();
        Mat3 rounded = exact;
        for (int e = 0; e < 9; ++e) rounded(e / 3, e % 3) += rng.uniform(-1e-3, 1e-3);
        const Mat3 nearest = nearest_rotation(rounded);
        EXPECT_TRUE(rotation_problem(nearest).empty()) << k;
        const double distance = (nearest - rounded).norm();
        EXPECT_LE(distance, (exact - rounded).norm() + 1e-15) << k;
        for (const Mat3& turn : {Mat3(Eigen::AngleAxisd(1e-4, Vec3::UnitX())), Mat3(Eigen::AngleAxisd(-1e-4, Vec3::UnitZ()))})
            EXPECT_LE(distance, (nearest * turn - rounded).norm() + 1e-15) << k;
    }
}

TEST(ValidatePose, AgreesWithTheFullProductAwayFromTheTolerance) {
    // The check computes six dot products of the columns, not R^T R; an independent oracle: Eigen's full
    // product and determinant, on perturbed rotations (and a non-finite entry in every position). Where the
    // oracle's measure lies within rounding of the tolerance either verdict is right, so those are skipped.
    SplitMix64 rng(29);
    int decided = 0;
    for (int k = 0; k < 20000; ++k) {
        RigidTransform pose{rng.rotation(), Vec3::Zero()};
        const double size = std::pow(10.0, rng.uniform(-12.0, -6.0));
        pose.rotation(static_cast<int>(rng.below(3)), static_cast<int>(rng.below(3))) += rng.uniform(-size, size);
        if (k % 5 == 0) pose.rotation.col(1) = -pose.rotation.col(1);
        const Mat3& r = pose.rotation;
        const double orthogonality = (r.transpose() * r - Mat3::Identity()).cwiseAbs().maxCoeff();
        const double determinant = std::abs(r.determinant() - 1.0);
        const auto near_tolerance = [](double v) { return std::abs(v - rotation_tolerance) < 1e-14; };
        if (near_tolerance(orthogonality) || near_tolerance(determinant)) continue;
        ++decided;
        EXPECT_EQ(is_rigid_motion(pose), orthogonality <= rotation_tolerance && determinant <= rotation_tolerance) << k;
    }
    EXPECT_GT(decided, 19000);
    for (const double bad : {nan, std::numeric_limits<double>::infinity()})
        for (int i = 0; i < 9; ++i) {
            RigidTransform pose;
            pose.rotation(i / 3, i % 3) = bad;
            EXPECT_FALSE(is_rigid_motion(pose)) << bad << " at " << i;
            EXPECT_NE(rotation_problem(pose.rotation).find("not finite"), std::string::npos);
        }
}

TEST(FromQuaternion, NormalisesAndMatchesAnAxisAngleRotation) {
    // A quaternion scaled by 7: the same rotation as the unit one, here 90 degrees about y.
    const double h = std::sqrt(0.5);
    const RigidTransform pose = RigidTransform::from_quaternion(7 * h, 0, 7 * h, 0, Vec3(1, 2, 3));
    const Mat3 expected = Eigen::AngleAxisd(std::numbers::pi / 2, Vec3::UnitY()).toRotationMatrix();
    EXPECT_LT((pose.rotation - expected).cwiseAbs().maxCoeff(), 1e-15);
    EXPECT_EQ(pose.translation, Vec3(1, 2, 3));
    // x -> z maps under +90 degrees about y to -x: a hand-computed point.
    EXPECT_LT((pose.apply(Vec3(0, 0, 1)) - Vec3(2, 2, 3)).norm(), 1e-15);
}

TEST(CheckFiniteExtent, RefusesNan) {
    // Eigen's min/max may skip a NaN operand; the NaN must not vanish in the merged box.
    std::vector<Primitive> primitives = good_primitives();
    primitives.push_back({Sphere{Vec3(nan, 0, 0), 1.0}, "nan"});
    const Status status = check_finite_extent(primitives);
    ASSERT_FALSE(status);
    EXPECT_NE(status.error().message.find("primitive 4"), std::string::npos) << status.error().message;
}

TEST(Build, RefusesBadGeometryNamingThePrimitive) {
    std::vector<Primitive> primitives = good_primitives();
    primitives[2] = {Sphere{Vec3(0, 0, 0), -1.0}, "negative"};
    for (const AlgorithmInfo& info : algorithms()) {
        const Result<Bvh> built = build(primitives, info.algorithm());
        ASSERT_FALSE(built) << info.name;
        EXPECT_NE(built.error().message.find("primitive 2 ('negative')"), std::string::npos) << built.error().message;
    }
}

TEST(QueryTree, RefusesANanVolumeInsteadOfPruningOnIt) {
    Bvh bvh = build(good_primitives(), Algorithm::split).value();
    bvh.nodes[0].volume = Sphere{Vec3(nan, 0, 0), 1.0};
    EXPECT_FALSE(QueryTree::create(bvh));
    EXPECT_THROW(QueryTree{bvh}, InvalidHierarchy);
    // The Bvh convenience overload reports it rather than answering "no contact".
    const CollideResult result = collide(bvh, RigidTransform::identity(), bvh, RigidTransform::identity());
    ASSERT_TRUE(result.error.has_value());
    EXPECT_FALSE(result.intersecting);
}

TEST(Collide, RefusesAPoseThatIsNoRotation) {
    const QueryTree tree(build(good_primitives(), Algorithm::split).value());
    RigidTransform sheared;
    sheared.rotation(0, 1) = 0.5;
    for (const CollideMode mode : {CollideMode::all, CollideMode::first}) {
        const CollideResult tandem = collide(tree, RigidTransform::identity(), tree, sheared, mode);
        ASSERT_TRUE(tandem.error.has_value());
        EXPECT_NE(tandem.error->message.find("pose_b"), std::string::npos) << tandem.error->message;
        EXPECT_TRUE(tandem.pairs.empty());
        const CollideResult two_level = collide_two_level(tree, sheared, tree, RigidTransform::identity(), mode);
        ASSERT_TRUE(two_level.error.has_value());
        EXPECT_NE(two_level.error->message.find("pose_a"), std::string::npos);
    }
    // The same query with a proper pose is answered, and the error is cleared on reuse.
    CollideResult reused;
    collide(tree, RigidTransform::identity(), tree, sheared, CollideMode::all, reused);
    collide(tree, RigidTransform::identity(), tree, RigidTransform::identity(), CollideMode::all, reused);
    EXPECT_FALSE(reused.error.has_value());
    EXPECT_TRUE(reused.intersecting);
}

}  // namespace
}  // namespace hbvh
