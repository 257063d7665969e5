// SPDX-License-Identifier: MIT
// Differential libFuzzer harness for the collision query: bytes -> a small primitive set (or two), two poses and
// two of the registered builders (any of them; the input picks, so each input stays fast and the corpus covers
// them all) -> validate() on each tree, and collide() in both modes against a brute force over all primitive pairs,
// done in collide()'s own frame convention (b's primitives moved into a's model frame by relative_transform with
// transformed(), as the leaf tests do), so that leaf tests match it bit for bit.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "hbvh/builders/build.hpp"
#include "hbvh/geometry/overlap.hpp"
#include "hbvh/query/tandem_traversal.hpp"
#include "hbvh/tree/validate.hpp"

namespace {

using hbvh::Aabb;
using hbvh::BoundingVolume;
using hbvh::Capsule;
using hbvh::Mat3;
using hbvh::Obb;
using hbvh::Primitive;
using hbvh::RigidTransform;
using hbvh::Sphere;
using hbvh::Vec3;
using Pair = std::pair<std::uint32_t, std::uint32_t>;

constexpr std::size_t max_primitives = 24;

/// The input bytes, read front to back; zeros once they run out (so every input decodes to some scene).
class ByteReader {
public:
    ByteReader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
    std::uint8_t byte() { return offset_ < size_ ? data_[offset_++] : 0; }
    int signed_byte() { return static_cast<std::int8_t>(byte()); }

private:
    const std::uint8_t* data_;
    std::size_t size_;
    std::size_t offset_ = 0;
};

/// Scene scales: a length unit for positions and sizes, and an offset added to every position (huge coordinates
/// with small primitives are where rounding of the transforms shows).
constexpr std::array<double, 6> units{1.0, 1e-6, 1e3, 1.0 / 1024.0, 3.0, 1e-3};
constexpr std::array<double, 6> offsets{0.0, 0.0, 1e6, 1e7, 1e8, -3e7};

/// A rotation whose entries are 0 and +-1 (exact 90-degree turns): they keep touching primitives touching.
Mat3 axis_rotation(std::uint8_t code) {
    static constexpr std::array<std::array<int, 3>, 6> permutations{
        {{0, 1, 2}, {1, 2, 0}, {2, 0, 1}, {1, 0, 2}, {0, 2, 1}, {2, 1, 0}}};
    const auto& p = permutations[code % 6];
    Mat3 r = Mat3::Zero();
    for (int i = 0; i < 3; ++i) r(i, p[static_cast<std::size_t>(i)]) = (code >> (3 + i)) & 1 ? -1.0 : 1.0;
    if (r.determinant() < 0.0) r.col(0) = -r.col(0);
    return r;
}

/// A rotation from four bytes: exact axis turns for a quarter of the codes, else a normalised quaternion
/// (identity when all four are zero).
Mat3 read_rotation(ByteReader& in) {
    const std::uint8_t code = in.byte();
    if (code % 4 == 0) return axis_rotation(static_cast<std::uint8_t>(code >> 2));
    Eigen::Quaterniond q(in.signed_byte(), in.signed_byte(), in.signed_byte(), in.signed_byte());
    if (q.squaredNorm() == 0.0) return Mat3::Identity();
    q.normalize();
    return q.toRotationMatrix();
}

struct SceneScale {
    double unit = 1.0;
    Vec3 offset = Vec3::Zero();
};

/// A position on a grid of unit/16 steps within +-8 units, plus the scene offset.
Vec3 read_position(ByteReader& in, const SceneScale& scale) {
    Vec3 p(in.signed_byte(), in.signed_byte(), in.signed_byte());
    return scale.offset + p * (scale.unit / 16.0);
}

/// A non-negative size: zero, tiny (1e-9 of the unit) or a grid step of unit/16 up to 2 units.
double read_size(ByteReader& in, const SceneScale& scale) {
    const std::uint8_t s = in.byte();
    if (s % 8 == 0) return 1e-9 * scale.unit * (1 + (s >> 3) % 4);
    if (s % 8 == 1) return 0.0;
    return (1 + (s >> 3)) * (scale.unit / 16.0);
}

/// A primitive of a fresh kind, or a copy of an earlier one (coincident), or one touching the previous one.
BoundingVolume read_volume(ByteReader& in, const SceneScale& scale, const std::vector<Primitive>& earlier) {
    const std::uint8_t kind = in.byte();
    switch (kind % 6) {
        case 0: {
            const Vec3 c = read_position(in, scale);
            const Vec3 h(read_size(in, scale), read_size(in, scale), read_size(in, scale));
            return Aabb{c - h, c + h};
        }
        case 1: {
            const Vec3 c = read_position(in, scale);
            const Vec3 h(read_size(in, scale), read_size(in, scale), read_size(in, scale));
            return Obb{c, read_rotation(in), h};
        }
        case 2: {
            const Vec3 c = read_position(in, scale);
            return Sphere{c, read_size(in, scale)};
        }
        case 3: {
            const Vec3 p0 = read_position(in, scale);
            // Direction from three bytes, times a size: zero-length capsules come out of both.
            const Vec3 d(in.signed_byte(), in.signed_byte(), in.signed_byte());
            const double length = read_size(in, scale);
            const Vec3 p1 = d.squaredNorm() > 0.0 ? Vec3(p0 + d.normalized() * length) : p0;
            return Capsule{p0, p1, read_size(in, scale)};
        }
        case 4:
            if (!earlier.empty()) return earlier[in.byte() % earlier.size()].volume;
            return Sphere{scale.offset, scale.unit};
        default: {
            // Touching the previous primitive's world box from outside on one axis: exact touching for boxes,
            // within rounding for round primitives.
            if (earlier.empty()) return Aabb{scale.offset, scale.offset + Vec3::Constant(scale.unit)};
            const Aabb prev = hbvh::world_aabb(earlier.back().volume);
            const std::uint8_t how = in.byte();
            const int axis = how % 3;
            const bool above = (how >> 2) & 1;
            Vec3 c = read_position(in, scale);
            const double size = std::max(read_size(in, scale), scale.unit / 16.0);
            if ((how >> 3) & 1) {
                c[axis] = above ? prev.max[axis] + size : prev.min[axis] - size;
                return Sphere{c, size};
            }
            Aabb box{c - Vec3::Constant(size), c + Vec3::Constant(size)};
            if (above) {
                box.min[axis] = prev.max[axis];
                box.max[axis] = prev.max[axis] + 2.0 * size;
            } else {
                box.max[axis] = prev.min[axis];
                box.min[axis] = prev.min[axis] - 2.0 * size;
            }
            return box;
        }
    }
}

/// 1 to `limit` primitives.
std::vector<Primitive> read_primitives(ByteReader& in, const SceneScale& scale, std::size_t limit) {
    const std::size_t count = std::min<std::size_t>(1 + in.byte() % max_primitives, limit);
    std::vector<Primitive> primitives;
    primitives.reserve(count);
    for (std::size_t i = 0; i < count; ++i) primitives.push_back({read_volume(in, scale, primitives), {}});
    return primitives;
}

/// Identity, a translation, an axis turn plus a translation, or a quaternion plus a translation; the
/// translation a grid position (so near the scene offset) or that minus the offset (near the origin).
RigidTransform read_pose(ByteReader& in, const SceneScale& scale) {
    const std::uint8_t code = in.byte();
    RigidTransform pose;
    if (code % 4 == 0) return pose;
    pose.translation = read_position(in, scale) - ((code >> 2) & 1 ? Vec3::Zero() : scale.offset);
    if (code % 4 == 2) pose.rotation = axis_rotation(in.byte());
    if (code % 4 == 3) pose.rotation = read_rotation(in);
    return pose;
}

hbvh::VolumePolicy read_policy(std::uint8_t code) {
    switch (code % 6) {
        case 1: return hbvh::VolumePolicy::only(hbvh::BvType::aabb);
        case 2: return hbvh::VolumePolicy::only(hbvh::BvType::sphere);
        case 3: return hbvh::VolumePolicy::only(hbvh::BvType::obb);
        case 4: return hbvh::VolumePolicy::only(hbvh::BvType::capsule);
        default: return hbvh::VolumePolicy::all();
    }
}

/// Largest input size at which a builder stays well under ~50 ms per input under the fuzzing sanitizers
/// (measured with HBVH_FUZZ_TIMING=1). Fitting OBBs and capsules to groups dominates, so the limits are lower
/// when the policy allows either; optimal's subset DP (and auto, optimal up to 10 primitives) doubles per
/// primitive, and the survey's B&B and bnb-exact search many candidate groups per level.
std::size_t size_limit(hbvh::Algorithm algorithm, bool fits_are_costly) {
    using hbvh::Algorithm;
    const auto is = [&](std::initializer_list<Algorithm> these) {
        return std::find(these.begin(), these.end(), algorithm) != these.end();
    };
    if (is({Algorithm::two_level})) return max_primitives;
    if (is({Algorithm::merge, Algorithm::obb_tree})) return fits_are_costly ? 14 : max_primitives;
    if (is({Algorithm::insertion, Algorithm::split, Algorithm::fast})) return fits_are_costly ? 10 : max_primitives;
    if (is({Algorithm::scale, Algorithm::binned}))
        return fits_are_costly ? 5 : 16;  // binned builds small inputs twice, fit_best per node
    if (is({Algorithm::insertion_haber})) return fits_are_costly ? 4 : max_primitives;
    if (is({Algorithm::bnb_enlarge})) return fits_are_costly ? 4 : 10;
    if (is({Algorithm::bnb_tightest, Algorithm::bnb_exact})) return fits_are_costly ? 3 : 8;
    if (is({Algorithm::optimal, Algorithm::automatic})) return fits_are_costly ? 4 : 8;
    return 3;  // a builder added since: as small as the exponential ones until it is timed
}

void print_volume(const BoundingVolume& bv) {
    std::visit(hbvh::Overloaded{
                   [](const Aabb& b) {
                       std::fprintf(stderr, "Aabb{{%.17g, %.17g, %.17g}, {%.17g, %.17g, %.17g}}", b.min.x(),
                                    b.min.y(), b.min.z(), b.max.x(), b.max.y(), b.max.z());
                   },
                   [](const Obb& b) {
                       const Mat3& r = b.rotation;
                       std::fprintf(stderr,
                                    "Obb{{%.17g, %.17g, %.17g}, rotation rows {%.17g, %.17g, %.17g; %.17g, %.17g, "
                                    "%.17g; %.17g, %.17g, %.17g}, half {%.17g, %.17g, %.17g}}",
                                    b.center.x(), b.center.y(), b.center.z(), r(0, 0), r(0, 1), r(0, 2), r(1, 0),
                                    r(1, 1), r(1, 2), r(2, 0), r(2, 1), r(2, 2), b.half_extents.x(),
                                    b.half_extents.y(), b.half_extents.z());
                   },
                   [](const Sphere& s) {
                       std::fprintf(stderr, "Sphere{{%.17g, %.17g, %.17g}, %.17g}", s.center.x(), s.center.y(),
                                    s.center.z(), s.radius);
                   },
                   [](const Capsule& c) {
                       std::fprintf(stderr, "Capsule{{%.17g, %.17g, %.17g}, {%.17g, %.17g, %.17g}, %.17g}", c.p0.x(),
                                    c.p0.y(), c.p0.z(), c.p1.x(), c.p1.y(), c.p1.z(), c.radius);
                   },
               },
               bv);
}

void print_pose(const char* name, const RigidTransform& pose) {
    const Mat3& r = pose.rotation;
    std::fprintf(stderr, "%s: rotation rows {%.17g, %.17g, %.17g; %.17g, %.17g, %.17g; %.17g, %.17g, %.17g}, "
                 "translation {%.17g, %.17g, %.17g}\n", name, r(0, 0), r(0, 1), r(0, 2), r(1, 0), r(1, 1), r(1, 2),
                 r(2, 0), r(2, 1), r(2, 2), pose.translation.x(), pose.translation.y(), pose.translation.z());
}

/// Everything a reproducer needs, then abort(): libFuzzer saves the input as a crash artifact.
[[noreturn]] void fail(const char* what, const std::vector<Primitive>& a, const std::vector<Primitive>& b,
                       const RigidTransform& pose_a, const RigidTransform& pose_b, std::string_view builder_a,
                       std::string_view builder_b, std::optional<Pair> pair) {
    std::fprintf(stderr, "fuzz_collide: %s (a built with %.*s, b with %.*s)\n", what,
                 static_cast<int>(builder_a.size()), builder_a.data(), static_cast<int>(builder_b.size()),
                 builder_b.data());
    if (pair) std::fprintf(stderr, "pair: a[%u] b[%u]\n", pair->first, pair->second);
    print_pose("pose_a", pose_a);
    print_pose("pose_b", pose_b);
    for (std::size_t i = 0; i < a.size(); ++i) {
        std::fprintf(stderr, "a[%zu] = ", i);
        print_volume(a[i].volume);
        std::fprintf(stderr, "\n");
    }
    if (&a != &b) {
        for (std::size_t i = 0; i < b.size(); ++i) {
            std::fprintf(stderr, "b[%zu] = ", i);
            print_volume(b[i].volume);
            std::fprintf(stderr, "\n");
        }
    }
    std::abort();
}

/// A length scale of the two volumes' configuration in a's frame: coordinates' magnitude and sizes.
double configuration_scale(const BoundingVolume& x, const BoundingVolume& y) {
    const Aabb box = hbvh::world_aabb(x).merged(hbvh::world_aabb(y));
    return std::max({box.min.cwiseAbs().maxCoeff(), box.max.cwiseAbs().maxCoeff(), (box.max - box.min).maxCoeff()});
}

/// The shortest move of b along one of the six axis directions that separates the two (bisection; up to
/// 1e-3 of the configuration's scale, infinity beyond): how deep a pair is, for the failure report.
double separating_move(const BoundingVolume& a_volume, const BoundingVolume& b_moved) {
    const double limit = 1e-3 * configuration_scale(a_volume, b_moved);
    double best = std::numeric_limits<double>::infinity();
    for (int axis = 0; axis < 3; ++axis) {
        for (const double sign : {-1.0, 1.0}) {
            const auto apart = [&](double step) {
                RigidTransform move;
                move.translation[axis] = sign * step;
                return !hbvh::overlaps(a_volume, hbvh::transformed(b_moved, move));
            };
            if (!apart(limit)) continue;
            double lo = 0.0, hi = limit;
            for (int i = 0; i < 80; ++i) {
                const double mid = 0.5 * (lo + hi);
                (apart(mid) ? hi : lo) = mid;
            }
            best = std::min(best, hi);
        }
    }
    return best;
}

/// A pair the brute force finds may be missed by the traversal only when it is within rounding of exact
/// touching: inner BVs are fitted with rounding (validate() allows 1e-9 of a node's size), and the pre-tests
/// are padded by 1e-12 of their own sizes. Such a pair separates when b moves by 2 * 1e-9 of the scale of the
/// configuration along one of the six axis directions (penetration depth up to 2 / sqrt(3) of that; a pair
/// of coincident points separates under any move). A pair that stays overlapping under all six moves is deep
/// enough that missing it is a bug.
/// HBVH_FUZZ_STRICT=1 in the environment counts every miss as a bug (to see how often touching pairs are
/// lost to rounding).
bool is_near_touching(const BoundingVolume& a_volume, const BoundingVolume& b_moved, double scene_scale) {
    static const bool strict = [] {
        const char* value = std::getenv("HBVH_FUZZ_STRICT");
        return value != nullptr && value[0] == '1';
    }();
    if (strict) return false;
    const double step = 2e-9 * std::max(scene_scale, configuration_scale(a_volume, b_moved));
    for (int axis = 0; axis < 3; ++axis) {
        for (const double sign : {-1.0, 1.0}) {
            RigidTransform move;
            move.translation[axis] = sign * step;
            if (!hbvh::overlaps(a_volume, hbvh::transformed(b_moved, move))) return true;
        }
    }
    return false;
}

/// Largest coordinate magnitude or extent of a primitive set (in its own model frame).
double set_scale(const std::vector<Primitive>& primitives) {
    Aabb box = Aabb::empty();
    for (const Primitive& p : primitives) box = box.merged(hbvh::world_aabb(p.volume));
    return std::max({box.min.cwiseAbs().maxCoeff(), box.max.cwiseAbs().maxCoeff(), (box.max - box.min).maxCoeff()});
}

struct Built {
    std::string_view name;
    hbvh::Bvh bvh;
};

/// `primitives` built with `info`'s builder, which must pass validate(); nullopt when the builder refuses the
/// input with an Error (it may, for degenerate geometry), never a crash or an invalid tree.
std::optional<Built> build_checked(const std::vector<Primitive>& primitives, const hbvh::AlgorithmInfo& info,
                                   const hbvh::VolumePolicy& policy) {
    // HBVH_FUZZ_TIMING=1 prints each build's time (to set size_limit).
    static const bool timing = std::getenv("HBVH_FUZZ_TIMING") != nullptr;
    hbvh::BuildContext options;
    options.policy = policy;
    const auto start = std::chrono::steady_clock::now();
    hbvh::Result<hbvh::Bvh> bvh = hbvh::build(primitives, info.algorithm(), options);
    if (timing)
        std::fprintf(stderr, "fuzz_collide: %zu primitives, %.*s: %.1f ms\n", primitives.size(),
                     static_cast<int>(info.name.size()), info.name.data(),
                     std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
    if (!bvh) return std::nullopt;
    if (hbvh::Status valid = hbvh::validate(*bvh); !valid) {
        std::fprintf(stderr, "fuzz_collide: validate() failed: %s\n", valid.error().to_string().c_str());
        fail("invalid tree", primitives, primitives, {}, {}, info.name, info.name, std::nullopt);
    }
    if (bvh->primitives.size() != primitives.size())
        fail("tree has a different primitive count", primitives, primitives, {}, {}, info.name, info.name,
             std::nullopt);
    return Built{info.name, std::move(bvh.value())};
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    ByteReader in(data, size);
    // Header: scene scale, policy, whether b is a second set and has a pose of its own, and the two builders
    // (one per input, so that each input stays fast; the corpus covers every pair of builders).
    const std::uint8_t scale_code = in.byte();
    SceneScale scale;
    scale.unit = units[scale_code % units.size()];
    const double offset = offsets[(scale_code >> 3) % offsets.size()];
    scale.offset = Vec3(offset, -0.5 * offset, 0.25 * offset);
    const std::uint8_t policy_code = in.byte();
    const hbvh::VolumePolicy policy = read_policy(policy_code);
    const bool fits_are_costly = policy.is_allowed(hbvh::BvType::obb) || policy.is_allowed(hbvh::BvType::capsule);
    const std::uint8_t flags = in.byte();
    const bool same_set = flags & 1;
    const bool same_pose = (flags >> 1) & 1;
    const std::span<const hbvh::AlgorithmInfo> registry = hbvh::algorithms();
    const hbvh::AlgorithmInfo& builder_a = registry[in.byte() % registry.size()];
    const hbvh::AlgorithmInfo& builder_b = same_set && (flags >> 2) & 1 ? builder_a
                                                                        : registry[in.byte() % registry.size()];
    const std::size_t limit_a = size_limit(builder_a.algorithm(), fits_are_costly);
    const std::size_t limit_b = size_limit(builder_b.algorithm(), fits_are_costly);

    const std::vector<Primitive> a = read_primitives(in, scale, same_set ? std::min(limit_a, limit_b) : limit_a);
    const std::vector<Primitive> b_own = same_set ? std::vector<Primitive>{} : read_primitives(in, scale, limit_b);
    const std::vector<Primitive>& b = same_set ? a : b_own;
    const RigidTransform pose_a = read_pose(in, scale);
    const RigidTransform pose_b = same_pose ? pose_a : read_pose(in, scale);

    // Brute force in collide()'s convention: a's primitives as they are, b's moved into a's model frame.
    const RigidTransform t = hbvh::relative_transform(pose_a, pose_b);
    std::vector<BoundingVolume> b_moved;
    b_moved.reserve(b.size());
    for (const Primitive& p : b) b_moved.push_back(hbvh::transformed(p.volume, t));
    std::vector<Pair> expected;
    for (std::uint32_t i = 0; i < a.size(); ++i)
        for (std::uint32_t j = 0; j < b.size(); ++j)
            if (hbvh::overlaps(a[i].volume, b_moved[j])) expected.emplace_back(i, j);
    const double scene_scale = std::max(set_scale(a), set_scale(b)) + pose_b.translation.cwiseAbs().maxCoeff() +
                               pose_a.translation.cwiseAbs().maxCoeff();

    const std::optional<Built> tree_a = build_checked(a, builder_a, policy);
    if (!tree_a) return 0;
    const std::optional<Built> tree_b_own =
        same_set && &builder_a == &builder_b ? std::nullopt : build_checked(b, builder_b, policy);
    const std::optional<Built>& tree_b = same_set && &builder_a == &builder_b ? tree_a : tree_b_own;
    if (!tree_b) return 0;

    const hbvh::QueryTree query_a(tree_a->bvh), query_b(tree_b->bvh);
    const auto report = [&](const char* what, std::optional<Pair> pair) {
        fail(what, a, b, pose_a, pose_b, tree_a->name, tree_b->name, pair);
    };
    const hbvh::CollideResult all = hbvh::collide(query_a, pose_a, query_b, pose_b, hbvh::CollideMode::all);
    if (!std::is_sorted(all.pairs.begin(), all.pairs.end()) ||
        std::adjacent_find(all.pairs.begin(), all.pairs.end()) != all.pairs.end())
        report("CollideMode::all: pairs not sorted or repeated", std::nullopt);
    if (all.intersecting != !all.pairs.empty())
        report("CollideMode::all: intersecting disagrees with pairs", std::nullopt);
    // Every reported pair must be a brute-force pair (the leaf test is the same arithmetic).
    for (const Pair& pair : all.pairs)
        if (!std::binary_search(expected.begin(), expected.end(), pair))
            report("collide reported a pair the brute force rejects", pair);
    // Every brute-force pair must be reported, unless it is within rounding of touching.
    for (const Pair& pair : expected)
        if (!std::binary_search(all.pairs.begin(), all.pairs.end(), pair) &&
            !is_near_touching(a[pair.first].volume, b_moved[pair.second], scene_scale)) {
            const double move = separating_move(a[pair.first].volume, b_moved[pair.second]);
            std::fprintf(stderr, "fuzz_collide: the pair separates after a move of %.3g (%.3g of its scale)\n", move,
                         move / configuration_scale(a[pair.first].volume, b_moved[pair.second]));
            report("collide missed a pair the brute force finds", pair);
        }

    const hbvh::CollideResult first = hbvh::collide(query_a, pose_a, query_b, pose_b, hbvh::CollideMode::first);
    if (first.pairs.size() > 1) report("CollideMode::first: more than one pair", std::nullopt);
    if (first.intersecting != all.intersecting)
        report("CollideMode::first and CollideMode::all disagree on intersecting", std::nullopt);
    if (first.intersecting != !first.pairs.empty())
        report("CollideMode::first: intersecting disagrees with pairs", std::nullopt);
    if (!first.pairs.empty() && !std::binary_search(expected.begin(), expected.end(), first.pairs.front()))
        report("CollideMode::first reported a pair the brute force rejects", first.pairs.front());
    if (first.pairs.empty())
        for (const Pair& pair : expected)
            if (!is_near_touching(a[pair.first].volume, b_moved[pair.second], scene_scale))
                report("CollideMode::first found nothing, but the brute force finds a pair", pair);
    return 0;
}
