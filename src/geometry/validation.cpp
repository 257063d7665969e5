// SPDX-License-Identifier: MIT
#include "hbvh/geometry/validation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <Eigen/SVD>

namespace hbvh {
namespace {

std::string number(double value) {
    char text[32];
    std::snprintf(text, sizeof text, "%.17g", value);
    return text;
}

/// Empty when `size` (a radius or half extent) is finite, >= 0 and not subnormal.
std::string size_problem(const char* what, double size) {
    if (!std::isfinite(size)) return std::string(what) + " is not a finite number";
    if (size < 0.0) return std::string(what) + " " + number(size) + " is negative";
    if (size > 0.0 && size < std::numeric_limits<double>::min())
        return std::string(what) + " " + number(size) + " is subnormal (too small to compute with)";
    return {};
}

std::string vector_problem(const char* what, const Vec3& v) {
    return v.allFinite() ? std::string{} : std::string(what) + " is not finite";
}

/// The first non-empty problem of a list.
template <class... Problems>
std::string first_of(Problems&&... problems) {
    std::string result;
    ((result.empty() ? void(result = std::forward<Problems>(problems)) : void()), ...);
    return result;
}

/// How far a matrix is from a proper rotation: the largest |R^T R - I| entry and the determinant. R^T R is
/// symmetric, so its six distinct entries (dot products of R's columns) are all there is to compute: the
/// check runs twice per query (both poses), where the full product and Eigen's reductions were 9 % of a
/// near-miss query's instructions.
struct RotationMeasures {
    double orthogonality;
    double determinant;
};

RotationMeasures measure_rotation(const Mat3& r) {
    const Vec3 x = r.col(0), y = r.col(1), z = r.col(2);
    const double orthogonality = std::max({std::abs(x.dot(x) - 1.0), std::abs(y.dot(y) - 1.0), std::abs(z.dot(z) - 1.0),
                                           std::abs(x.dot(y)), std::abs(x.dot(z)), std::abs(y.dot(z))});
    return {orthogonality, x.dot(y.cross(z))};
}

/// The criterion of a proper rotation, for rotation_problem and is_rigid_motion alike: finite, orthonormal and
/// of determinant 1, each within rotation_tolerance. The identity, the usual pose of a fixed object, is
/// answered by comparison alone.
bool is_rotation(const Mat3& r) {
    if (r == Mat3::Identity()) return true;
    const RotationMeasures m = measure_rotation(r);
    // std::max can drop a NaN measure (its comparisons are false), so finiteness is still tested: last, as
    // the cheap tests reject most bad matrices first.
    return m.orthogonality <= rotation_tolerance && std::abs(m.determinant - 1.0) <= rotation_tolerance &&
           r.allFinite();
}

}  // namespace

Mat3 nearest_rotation(const Mat3& m) {
    const Eigen::JacobiSVD<Mat3> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
    return svd.matrixU() * svd.matrixV().transpose();
}

Mat3 exact_rotation(const Mat3& rotation) {
    constexpr double rounding_only = 2e-15;
    if (rotation == Mat3::Identity() || measure_rotation(rotation).orthogonality <= rounding_only) return rotation;
    return nearest_rotation(rotation);
}

std::string rotation_problem(const Mat3& rotation) {
    if (is_rotation(rotation)) return {};
    // Which condition failed, in the order of is_rotation, with its number.
    if (!rotation.allFinite()) return "rotation is not finite";
    const RotationMeasures m = measure_rotation(rotation);
    if (!(m.orthogonality <= rotation_tolerance))
        return "rotation is not orthonormal: |R^T R - I| = " + number(m.orthogonality);
    if (!(std::abs(m.determinant - 1.0) <= rotation_tolerance))
        return "rotation is a reflection (determinant " + number(m.determinant) + "), not a rotation";
    return {};
}

std::string volume_problem(const BoundingVolume& volume) {
    return std::visit(
        Overloaded{
            [](const Aabb& box) {
                return first_of(vector_problem("min corner", box.min), vector_problem("max corner", box.max),
                                vector_problem("extent (max - min)", Vec3(box.max - box.min)),
                                size_problem("x extent (max - min)", box.max.x() - box.min.x()),
                                size_problem("y extent (max - min)", box.max.y() - box.min.y()),
                                size_problem("z extent (max - min)", box.max.z() - box.min.z()));
            },
            [](const Obb& box) {
                return first_of(vector_problem("centre", box.center), rotation_problem(box.rotation),
                                size_problem("x half extent", box.half_extents.x()),
                                size_problem("y half extent", box.half_extents.y()),
                                size_problem("z half extent", box.half_extents.z()),
                                vector_problem("extent", Vec3(2.0 * box.half_extents)));
            },
            [](const Sphere& sphere) {
                return first_of(vector_problem("centre", sphere.center), size_problem("radius", sphere.radius));
            },
            [](const Capsule& capsule) {
                std::string length = std::isfinite(capsule.length()) && capsule.center().allFinite()
                                         ? std::string{}
                                         : "length or centre overflows the range of double";
                return first_of(vector_problem("p0", capsule.p0), vector_problem("p1", capsule.p1),
                                size_problem("radius", capsule.radius), std::move(length));
            },
        },
        volume);
}

Status validate_primitives(std::span<const Primitive> primitives) {
    for (std::size_t i = 0; i < primitives.size(); ++i) {
        // Both file formats end a name at a NUL (XML cannot hold one, the binary reader refuses it): such a name
        // would come back cut short, so it is refused here rather than changed on saving.
        if (primitives[i].name.find('\0') != std::string::npos)
            return Error{"primitive " + std::to_string(i) + ": its name holds a NUL byte, which no hierarchy file keeps"};
        std::string problem = volume_problem(primitives[i].volume);
        if (problem.empty()) continue;
        std::string where = "primitive " + std::to_string(i);
        if (!primitives[i].name.empty()) where += " ('" + primitives[i].name + "')";
        return Error{where + " (" + std::string(to_string(type_of(primitives[i].volume))) + "): " + problem};
    }
    return Ok{};
}

bool is_rigid_motion(const RigidTransform& pose) { return pose.translation.allFinite() && is_rotation(pose.rotation); }

std::string pose_problem(const RigidTransform& pose) {
    if (is_rigid_motion(pose)) return {};
    if (!pose.translation.allFinite()) return "translation is not finite";
    return rotation_problem(pose.rotation);
}

Status validate_pose(const RigidTransform& pose) {
    if (std::string problem = pose_problem(pose); !problem.empty()) return Error{"pose: " + problem};
    return Ok{};
}

}  // namespace hbvh
