// SPDX-License-Identifier: MIT
// Precision anywhere in the world (docs/reliability.md, "Precision"): moving a whole scene by a rigid motion
// must not change which primitive pairs collide, except pairs within a band of touching relative to the
// coordinates; and resting contacts kilometres from the origin must be found, however small the objects.
#include <gtest/gtest.h>

#include <ccd/ccd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "hbvh/builders/build.hpp"
#include "hbvh/geometry/overlap.hpp"
#include "hbvh/query/tandem_traversal.hpp"
#include "hbvh/scene/generate.hpp"

namespace hbvh {
namespace {

using Pairs = std::vector<std::pair<std::uint32_t, std::uint32_t>>;

/// Primitives per object: small enough that the metamorphic test takes about a second per builder or less
/// (release build, per tree at 12 primitives: 1-40 ms for most builders; optimal ~0.6 s, auto 0.3-0.5 s,
/// bnb-exact 0.1-0.12 s and bnb-tightest 75-90 ms, which get 8: 20-50 ms). Each test builds 40 trees per
/// builder; at 12 primitives bnb-exact's and bnb-tightest's took 45-65 s and 25-55 s under the sanitizers.
std::uint32_t primitive_count(Algorithm algorithm) {
    const bool exponential = algorithm == Algorithm::optimal || algorithm == Algorithm::automatic ||
                             algorithm == Algorithm::bnb_exact || algorithm == Algorithm::bnb_tightest;
    return exponential ? 8 : 12;
}

/// The band in which a pair may change its answer when the scene moves: 1e-12 of the coordinates' magnitude
/// plus 1e-12 of the objects' size (overlaps() itself accepts gaps up to ~1e-13 of the coordinates).
double precision_band(double coordinates, double size) { return 1e-12 * coordinates + 1e-12 * size; }

// Independent separation check (libccd MPR on grown and shrunk primitives).

/// A primitive grown (grow > 0: Minkowski sum with a ball) or shrunk (grow < 0: erosion by a ball, exact for
/// boxes, spheres and capsules), seen from `origin` at zoom `unit` (libccd's tolerances are absolute).
struct Body {
    BoundingVolume volume;
    double grow = 0.0;
    Vec3 origin = Vec3::Zero();
    double unit = 1.0;
};

/// False when the shrinking left nothing.
bool is_nonempty(const Body& body) {
    return std::visit(
        [&](const auto& v) {
            using T = std::decay_t<decltype(v)>;
            if constexpr (std::is_same_v<T, Aabb>) return (v.half_extents().array() + std::min(body.grow, 0.0) >= 0.0).all();
            else if constexpr (std::is_same_v<T, Obb>) return (v.half_extents.array() + std::min(body.grow, 0.0) >= 0.0).all();
            else return v.radius + body.grow >= 0.0;
        },
        body.volume);
}

Vec3 box_support(const Vec3& center, const Mat3& axes, const Vec3& half, double grow, const Vec3& dir) {
    // Erosion shrinks the half extents; growth adds a ball (rounded edges), i.e. grow along the direction.
    const Vec3 h = half.array() + std::min(grow, 0.0);
    Vec3 point = center;
    for (int k = 0; k < 3; ++k) point += (axes.col(k).dot(dir) >= 0.0 ? h[k] : -h[k]) * axes.col(k);
    return point + std::max(grow, 0.0) * dir;
}

/// Support point of the body in direction `dir` (unit), relative to its origin, before the zoom.
Vec3 support_local(const Body& body, const Vec3& dir) {
    return std::visit(
        [&](const auto& v) -> Vec3 {
            using T = std::decay_t<decltype(v)>;
            if constexpr (std::is_same_v<T, Aabb>)
                return box_support(v.center() - body.origin, Mat3::Identity(), v.half_extents(), body.grow, dir);
            else if constexpr (std::is_same_v<T, Obb>)
                return box_support(v.center - body.origin, v.rotation, v.half_extents, body.grow, dir);
            else if constexpr (std::is_same_v<T, Sphere>)
                return v.center - body.origin + (v.radius + body.grow) * dir;
            else
                return ((v.p1 - v.p0).dot(dir) >= 0.0 ? v.p1 : v.p0) - body.origin + (v.radius + body.grow) * dir;
        },
        body.volume);
}

void body_support(const void* object, const ccd_vec3_t* dir, ccd_vec3_t* out) {
    const Body& body = *static_cast<const Body*>(object);
    const Vec3 d(dir->v[0], dir->v[1], dir->v[2]);
    const double n = d.norm();
    const Vec3 s = body.unit * support_local(body, n > 0.0 ? Vec3(d / n) : Vec3::UnitX());
    for (int k = 0; k < 3; ++k) out->v[k] = s[k];
}

void body_center(const void* object, ccd_vec3_t* out) {
    const Body& body = *static_cast<const Body*>(object);
    // The midpoint of two opposite support points lies inside the convex body.
    const Vec3 c = 0.5 * body.unit * (support_local(body, Vec3::UnitX()) + support_local(body, -Vec3::UnitX()));
    for (int k = 0; k < 3; ++k) out->v[k] = c[k];
}

bool bodies_intersect(const Body& a, const Body& b) {
    if (!is_nonempty(a) || !is_nonempty(b)) return false;
    ccd_t ccd;
    CCD_INIT(&ccd);
    ccd.support1 = ccd.support2 = body_support;
    ccd.center1 = ccd.center2 = body_center;
    ccd.max_iterations = 1000;
    ccd.mpr_tolerance = 1e-15;
    return ccdMPRIntersect(&a, &b, &ccd) != 0;
}

/// True when a and b (one frame) are within `band` of touching: grown by band / 2 each they meet, shrunk by
/// band / 2 each they do not. Computed independently of overlaps(), at unit size near the pair.
bool within_band(const BoundingVolume& a, const BoundingVolume& b, double band) {
    const double size = std::max(size_scale(a), size_scale(b));
    const Vec3 origin = world_aabb(a).center();
    const double unit = 1.0 / size;
    const bool grown = bodies_intersect({a, 0.5 * band, origin, unit}, {b, 0.5 * band, origin, unit});
    const bool shrunk = bodies_intersect({a, -0.5 * band, origin, unit}, {b, -0.5 * band, origin, unit});
    return grown && !shrunk;
}

// Scenes and motions.

/// The primitives moved by `m`; Aabbs stay Aabbs under a pure translation (else they become Obbs).
std::vector<Primitive> moved(const std::vector<Primitive>& primitives, const RigidTransform& m) {
    std::vector<Primitive> out = primitives;
    for (Primitive& p : out) {
        if (const auto* box = std::get_if<Aabb>(&p.volume); box != nullptr && m.rotation == Mat3::Identity())
            p.volume = Aabb{box->min + m.translation, box->max + m.translation};
        else
            p.volume = transformed(p.volume, m);
    }
    return out;
}

Bvh build_or_die(const std::vector<Primitive>& primitives, Algorithm algorithm) {
    auto built = build(primitives, algorithm);
    EXPECT_TRUE(built.has_value()) << to_string(algorithm);
    return built.has_value() ? std::move(built).value() : Bvh{};
}

Pairs brute_force(const std::vector<Primitive>& a, const std::vector<Primitive>& b_in_a) {
    Pairs pairs;
    for (std::uint32_t i = 0; i < a.size(); ++i)
        for (std::uint32_t j = 0; j < b_in_a.size(); ++j)
            if (overlaps(a[i].volume, b_in_a[j].volume)) pairs.emplace_back(i, j);
    return pairs;
}

double scene_radius(const std::vector<Primitive>& primitives) {
    Aabb box = Aabb::empty();
    for (const Primitive& p : primitives) box = box.merged(world_aabb(p.volume));
    return 0.5 * (box.max - box.min).norm();
}

/// b's pose at the origin: b's primitive j centred on a's primitive i, randomly turned, then pushed along a
/// random direction to where the pair just stops overlapping (bisection on overlaps()): that pair touches
/// within ulps, so the band is exercised; the other pairs interpenetrate at random depths.
RigidTransform touching_pose(const std::vector<Primitive>& a, const std::vector<Primitive>& b, SplitMix64& rng) {
    const BoundingVolume& pa = a[rng.below(a.size())].volume;
    const BoundingVolume& pb = b[rng.below(b.size())].volume;
    const Mat3 turn = rng.rotation();
    const Vec3 direction = rng.rotation().col(0);
    const Vec3 start = world_aabb(pa).center() - turn * world_aabb(pb).center();
    const auto pose = [&](double d) { return RigidTransform{turn, start + d * direction}; };
    double lo = 0.0, hi = 4.0 * (size_scale(pa) + size_scale(pb));
    for (int k = 0; k < 100; ++k) {
        const double mid = 0.5 * (lo + hi);
        (overlaps(pa, transformed(pb, pose(mid))) ? lo : hi) = mid;
    }
    return pose(lo);
}

/// Pairs found in one answer and not the other must be within the band (judged at the origin); returns
/// how many such in-band differences there were.
int expect_same_up_to_band(const Pairs& at_origin, const Pairs& moved_pairs, const std::vector<Primitive>& a,
                           const std::vector<Primitive>& b_in_a, double coordinates, const std::string& what) {
    Pairs differing;
    std::set_symmetric_difference(at_origin.begin(), at_origin.end(), moved_pairs.begin(), moved_pairs.end(),
                                  std::back_inserter(differing));
    for (const auto& [i, j] : differing) {
        const BoundingVolume& x = a[i].volume;
        const BoundingVolume& y = b_in_a[j].volume;
        const double band = precision_band(coordinates, std::max(size_scale(x), size_scale(y)));
        EXPECT_TRUE(within_band(x, y, band)) << what << ": pair (" << i << ", " << j << ") changed its answer "
                                              << "but is not within " << band << " of touching";
    }
    return static_cast<int>(differing.size());
}

// Metamorphic: the whole scene moved.

class PrecisionPerBuilder : public ::testing::TestWithParam<AlgorithmInfo> {};

TEST_P(PrecisionPerBuilder, RigidMotionsKeepThePairsUpToTheBand) {
    const Algorithm algorithm = GetParam().algorithm();
    int compared = 0, in_band = 0;
    const std::uint32_t count = primitive_count(algorithm);
    for (std::uint64_t seed = 1; seed <= 2; ++seed) {
        SplitMix64 rng(0x9e3779b9u * seed);
        const std::vector<Primitive> a = generate_scene({.count = count, .seed = 100 + seed});
        const std::vector<Primitive> b = generate_scene({.count = count, .seed = 200 + seed});
        const RigidTransform pose_b = touching_pose(a, b, rng);
        const std::vector<Primitive> b_at_origin = moved(b, pose_b);
        const Bvh tree_a = build_or_die(a, algorithm), tree_b = build_or_die(b, algorithm);
        const Pairs at_origin = collide(tree_a, RigidTransform::identity(), tree_b, pose_b).pairs;
        // At the origin the traversal is the brute force (test_tandem_traversal.cpp covers this widely).
        EXPECT_EQ(at_origin, brute_force(a, b_at_origin)) << "seed " << seed;
        const double radius = scene_radius(a) + scene_radius(b);
        for (const double offset : {1.0, 1e3, 1e5}) {
            for (const bool turn : {true, false}) {
                const RigidTransform m{turn ? rng.rotation() : Mat3::Identity(), offset * rng.rotation().col(0)};
                const double coordinates = offset + radius;
                const std::string what = std::string(to_string(algorithm)) + " seed " + std::to_string(seed) +
                                         " offset " + std::to_string(offset) + (turn ? " turned" : "");
                // As poses: the same trees, both poses premultiplied by the motion.
                const Pairs as_poses = collide(tree_a, m, tree_b, m * pose_b).pairs;
                in_band += expect_same_up_to_band(at_origin, as_poses, a, b_at_origin, coordinates, what + " (poses)");
                // As geometry: the primitives themselves far from the origin, the trees rebuilt over them.
                const std::vector<Primitive> far_a = moved(a, m), far_b = moved(b, m * pose_b);
                const Pairs as_geometry =
                    collide(build_or_die(far_a, algorithm), RigidTransform::identity(), build_or_die(far_b, algorithm),
                            RigidTransform::identity())
                        .pairs;
                in_band +=
                    expect_same_up_to_band(at_origin, as_geometry, a, b_at_origin, coordinates, what + " (geometry)");
                // Both at once: b's geometry far away and a pose that brings it back, so that the query's
                // relative transform has a large translation. Leaves are tested with the brute force's own
                // arithmetic, so any difference would be a pre-test rejecting what the exact test accepts.
                const RigidTransform back = pose_b * m.inverse();
                const Pairs mixed = collide(tree_a, RigidTransform::identity(), build_or_die(moved(b, m), algorithm), back).pairs;
                std::vector<Primitive> far_b_in_a = moved(b, m);
                for (Primitive& p : far_b_in_a) p.volume = transformed(p.volume, relative_transform(RigidTransform::identity(), back));
                EXPECT_EQ(mixed, brute_force(a, far_b_in_a)) << what << " (far geometry, pose back)";
                compared += 3;
            }
        }
    }
    RecordProperty("in_band_differences", in_band);
    std::printf("[ precision ] %s: %d moved scenes, %d in-band differences\n",
                std::string(to_string(algorithm)).c_str(), compared, in_band);
}

INSTANTIATE_TEST_SUITE_P(EveryAlgorithm, PrecisionPerBuilder, ::testing::ValuesIn(algorithms().begin(), algorithms().end()),
                         [](const ::testing::TestParamInfo<AlgorithmInfo>& param_info) {
                             std::string name(param_info.param.name);
                             std::replace(name.begin(), name.end(), '-', '_');
                             return name;
                         });

// Resting contacts far from the origin.

/// Two objects in one scene frame whose `contacts` pairs (a's primitive, b's primitive) rest on each other
/// at a penetration of 1e-9 of the size; the rest of each object lies well away from the contact, so that
/// the trees have inner nodes to descend through.
struct RestingScene {
    std::vector<Primitive> a, b;
    Pairs contacts;
};

/// Filler primitives of size ~s in the slab `z_low` < z < `z_high` (well away from the contact).
void add_filler(std::vector<Primitive>& out, SplitMix64& rng, double s, double z_low, double z_high, int count) {
    for (int k = 0; k < count; ++k) {
        const Vec3 c(rng.uniform(-2 * s, 2 * s), rng.uniform(-2 * s, 2 * s), rng.uniform(z_low, z_high));
        const double r = 0.2 * s;
        switch (k % 3) {
            case 0: out.push_back({Sphere{c, r}, {}}); break;
            case 1: out.push_back({Obb{c, rng.rotation(), Vec3(r, 0.5 * r, r)}, {}}); break;
            default: out.push_back({Capsule{c - Vec3(r, 0, 0), c + Vec3(r, 0, 0), 0.5 * r}, {}}); break;
        }
    }
}

/// Scene `kind` (0 box on box, 1 sphere on box, 2 capsule on capsule, 3 capsule in a box corner) of size s,
/// the contacts `p` deep. Contacts lie in the plane z = 0; a is below it, b above.
RestingScene resting_scene(int kind, double s, double p, SplitMix64 rng) {
    RestingScene scene;
    const Mat3 yaw = Eigen::AngleAxisd(rng.uniform(0, 6.3), Vec3::UnitZ()).toRotationMatrix();
    switch (kind) {
        case 0:
            scene.a.push_back({Obb{Vec3(0, 0, -0.5 * s), Mat3::Identity(), Vec3(s, s, 0.5 * s)}, {}});
            scene.b.push_back({Obb{Vec3(0.3 * s, -0.2 * s, 0.25 * s - p), yaw, Vec3(0.4 * s, 0.3 * s, 0.25 * s)}, {}});
            break;
        case 1:
            scene.a.push_back({Obb{Vec3(0, 0, -0.5 * s), yaw, Vec3(s, s, 0.5 * s)}, {}});
            scene.b.push_back({Sphere{Vec3(0.2 * s, 0.1 * s, 0.3 * s - p), 0.3 * s}, {}});
            break;
        case 2: {
            const double r = 0.2 * s;
            scene.a.push_back({Capsule{Vec3(-s, 0, -r), Vec3(s, 0, -r), r}, {}});
            const Vec3 axis = yaw.col(0) * s;
            scene.b.push_back({Capsule{Vec3(0, 0, r - p) - axis, Vec3(0, 0, r - p) + axis, r}, {}});
            break;
        }
        default: {
            // Floor z < 0 and a wall x < 0; the capsule lies along the corner line, on both.
            const double r = 0.2 * s;
            scene.a.push_back({Obb{Vec3(0.5 * s, 0, -0.5 * s), Mat3::Identity(), Vec3(1.5 * s, s, 0.5 * s)}, {}});
            scene.a.push_back({Obb{Vec3(-0.5 * s, 0, 0.5 * s), Mat3::Identity(), Vec3(0.5 * s, s, 0.5 * s)}, {}});
            scene.b.push_back({Capsule{Vec3(r - p, -0.8 * s, r - p), Vec3(r - p, 0.8 * s, r - p), r}, {}});
            scene.contacts.emplace_back(1, 0);
            break;
        }
    }
    scene.contacts.emplace_back(0, 0);
    std::sort(scene.contacts.begin(), scene.contacts.end());
    add_filler(scene.a, rng, s, -4 * s, -2 * s, 6);
    add_filler(scene.b, rng, s, 2.5 * s, 4.5 * s, 6);
    return scene;
}

std::string scene_name(int kind) {
    static const char* const names[] = {"box on box", "sphere on box", "capsule on capsule", "capsule in a box corner"};
    return names[kind];
}

/// The builders the resting contacts go through: flat, top-down, bottom-up, incremental, exact, parallel.
constexpr Algorithm resting_builders[] = {Algorithm::two_level, Algorithm::split,     Algorithm::merge,
                                          Algorithm::insertion, Algorithm::obb_tree,  Algorithm::bnb_exact,
                                          Algorithm::scale,     Algorithm::automatic};

/// True when every contact of `scene` is among `pairs`; adds a failure naming the contact otherwise.
void expect_contacts(const Pairs& pairs, const RestingScene& scene, const std::string& what) {
    for (const auto& contact : scene.contacts)
        EXPECT_TRUE(std::binary_search(pairs.begin(), pairs.end(), contact))
            << what << ": contact (" << contact.first << ", " << contact.second << ") missed";
}

TEST(Precision, RestingContactsFarFromTheOriginAreFound) {
    // Penetrations of 1e-9 of sizes down to 1e-3 are 1e-12 deep: at 1e5 the coordinates round at ~1e-11,
    // so only the coordinate slacks keep these contacts.
    // Eight trials per offset: each of the four scenes small (1 to 10 mm for metres, where the coordinates'
    // rounding dominates) and large (1 cm to 1 m), the small ones and the large box on box turned, the other
    // large ones not. (Sixteen trials ran this pattern twice with other random sizes and poses, for twice the
    // time: 57 s under the sanitizers, most of it auto's and bnb-exact's builds.)
    SplitMix64 rng(2024);
    int queries = 0;
    for (const double offset : {1e3, 1e5}) {
        for (int trial = 0; trial < 8; ++trial) {
            const int kind = trial % 4;
            const bool small = trial < 4;
            const double s = small ? std::pow(10.0, -rng.uniform(2.0, 3.0)) : std::pow(10.0, -rng.uniform(0.0, 2.0));
            const SplitMix64 scene_rng(rng.next());
            const RestingScene scene = resting_scene(kind, s, 1e-9 * s, scene_rng);
            // b's model frame: its own placement in the scene; a's model frame is the scene's.
            const RigidTransform place_b{rng.rotation(), s * Vec3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1))};
            const RigidTransform m{trial < 5 ? rng.rotation() : Mat3::Identity(), offset * rng.rotation().col(0)};
            const std::string what = scene_name(kind) + " size " + std::to_string(s) + " offset " + std::to_string(offset);
            // As geometry: model coordinates far from the origin, trees built over them.
            const std::vector<Primitive> far_a = moved(scene.a, m), far_b = moved(moved(scene.b, place_b.inverse()), m * place_b);
            for (const auto& [i, j] : scene.contacts)
                EXPECT_TRUE(overlaps(far_a[i].volume, far_b[j].volume)) << what << " plain overlaps()";
            // As poses: model frames near the origin, poses far. The two poses are each rounded at ~1e-16 of
            // their translation before the query sees them, and collide() does not know their magnitude (it
            // works in a's model frame), so these contacts are 1e-13 of the offset deeper (see
            // docs/reliability.md, "Precision").
            const RestingScene posed = resting_scene(kind, s, 1e-9 * s + 1e-13 * offset, scene_rng);
            const std::vector<Primitive> posed_b = moved(posed.b, place_b.inverse());
            for (const Algorithm algorithm : resting_builders) {
                const std::string by = what + " " + std::string(to_string(algorithm));
                expect_contacts(collide(build_or_die(far_a, algorithm), RigidTransform::identity(),
                                        build_or_die(far_b, algorithm), RigidTransform::identity())
                                    .pairs,
                                scene, by + " (geometry)");
                expect_contacts(collide(build_or_die(posed.a, algorithm), m, build_or_die(posed_b, algorithm), m * place_b)
                                    .pairs,
                                posed, by + " (poses)");
                queries += 2;
            }
        }
    }
    EXPECT_EQ(queries, 2 * 8 * 2 * 8);
}

TEST(Precision, BandCheckSeparatesClearCasesFromTouching) {
    // The in-band judgement must itself be able to say no: a gap or a penetration of 1e-6 of the size is
    // far outside a 1e-12 band, touching (within ulps) is inside.
    const Obb box{Vec3(3, -2, 1), Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix(), Vec3(1, 0.5, 2)};
    const Vec3 normal = box.rotation.col(0);
    for (const double d : {-1e-6, 1e-6, 0.0}) {
        const Sphere s{box.center + (1.0 + 0.25 + d) * normal, 0.25};
        EXPECT_EQ(within_band(box, s, 1e-12 * 4), d == 0.0) << d;
    }
}

}  // namespace
}  // namespace hbvh
