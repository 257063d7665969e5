// SPDX-License-Identifier: MIT
// hbvh_peers: hbvh's tandem traversal side by side with Bullet's compound shapes and FCL's dynamic AABB
// tree managers, on the same objects and the same seeded poses, with a check that all find the same pairs.
#include <fmt/core.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <optional>
#include <type_traits>
#include <string>
#include <string_view>
#include <vector>

#include "hbvh/builders/build.hpp"
#include "hbvh/geometry/overlap.hpp"
#include "hbvh/query/tandem_traversal.hpp"
#include "hbvh/scene/generate.hpp"
#include "hbvh/tree/stats.hpp"
#include "../common/bench_objects.hpp"
#include "peer.hpp"

namespace hbvh::peers {

LocalShape to_local_shape(const BoundingVolume& volume) {
    LocalShape out;
    if (const auto* box = std::get_if<Aabb>(&volume)) {
        out.kind = LocalShape::Kind::box;
        out.frame.translation = box->center();
        out.half_extents = box->half_extents();
    } else if (const auto* obb = std::get_if<Obb>(&volume)) {
        out.kind = LocalShape::Kind::box;
        out.frame = {obb->rotation, obb->center};
        out.half_extents = obb->half_extents;
    } else if (const auto* sphere = std::get_if<Sphere>(&volume)) {
        out.kind = LocalShape::Kind::sphere;
        out.frame.translation = sphere->center;
        out.radius = sphere->radius;
    } else {
        const auto& capsule = std::get<Capsule>(volume);
        out.radius = capsule.radius;
        out.length = capsule.length();
        out.frame.translation = capsule.center();
        out.kind = out.length > 0.0 ? LocalShape::Kind::capsule : LocalShape::Kind::sphere;
        out.frame.rotation = Eigen::Quaterniond::FromTwoVectors(Vec3::UnitZ(), capsule.direction()).toRotationMatrix();
    }
    return out;
}

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

double median(std::vector<double> values) {
    std::sort(values.begin(), values.end());
    return values.empty() ? 0.0 : values[values.size() / 2];
}

using Object = bench::BenchObject;

enum class Regime { partial, near, total };
constexpr std::string_view regime_name(Regime regime) {
    return regime == Regime::partial ? "partial" : regime == Regime::near ? "near" : "total";
}

/// How many pairs a peer found like hbvh, unlike hbvh, and unlike hbvh but too close to call.
struct Agreement {
    std::uint64_t agree = 0;      ///< Found by both.
    std::uint64_t peer_only = 0;  ///< Found by the peer only, separated by more than the tolerance.
    std::uint64_t hbvh_only = 0;  ///< Found by hbvh only, penetrating by more than the tolerance.
    std::uint64_t close = 0;      ///< Found by one only, but within the tolerance of touching: not counted.
};

/// The volume grown (delta > 0) or shrunk (delta < 0) by |delta| in every direction (boxes: on each face).
BoundingVolume offset(const BoundingVolume& volume, double delta) {
    return std::visit(
        [delta](auto v) -> BoundingVolume {
            using T = decltype(v);
            if constexpr (std::is_same_v<T, Aabb>) {
                const Vec3 c = v.center();
                const Vec3 h = (v.half_extents().array() + delta).max(0.0);
                return Aabb{c - h, c + h};
            } else if constexpr (std::is_same_v<T, Obb>) {
                v.half_extents = (v.half_extents.array() + delta).max(0.0);
                return v;
            } else {
                v.radius = std::max(v.radius + delta, 0.0);
                return v;
            }
        },
        volume);
}

struct Row {
    std::string object;
    std::size_t primitives = 0;
    Regime regime = Regime::partial;
    std::size_t poses = 0;
    double hbvh_us = 0, two_level_us = 0, bullet_us = 0, fcl_us = 0, fcl_collide_us = 0;
    double hbvh_first_us = 0, two_level_first_us = 0;  ///< CollideMode::first (hbvh only: the peers' "any contact" modes differ).
    std::uint64_t hbvh_pairs = 0;
    Agreement bullet, fcl;
};

struct BuildRow {
    std::string object;
    std::size_t primitives = 0;
    double hbvh_ms = 0, bullet_ms = 0, fcl_ms = 0;
    double hbvh_cost = 0, bullet_cost = 0, fcl_cost = 0;
    double fast_ms = 0, fast_cost = 0;  ///< The speed preset (`--quality fast`), built beside the default.
};

struct Options {
    bool markdown = false;
    std::size_t poses = 32;
    int repetitions = 7;
    double tolerance = 1e-6;  ///< Relative to the object's size: pairs closer than this to touching are not judged.
    std::string only;         ///< When set, only objects whose name contains it.
    bool fastest = false;     ///< Query rows give the fastest repetition instead of the median.
    bool build_only = false;  ///< Only the build table (no queries).
};

Algorithm pick_algorithm() {
    for (std::string_view name : {"auto", "bnb-enlarge", "two-level"})
        if (auto algorithm = parse_algorithm(name)) return *algorithm;
    return algorithms().front().algorithm();
}

/// Fixed seeded poses of copy b for one regime. partial: random rotation and offset with the root BVs
/// overlapping; near: the same, but also no primitive pair overlapping (hbvh's exact answer); total: identity.
std::vector<RigidTransform> make_poses(const Bvh& bvh, const QueryTree& tree, Regime regime, std::size_t count) {
    if (regime == Regime::total) return std::vector<RigidTransform>(count, RigidTransform::identity());
    Aabb bounds = Aabb::empty();
    for (const Primitive& p : bvh.primitives) bounds = bounds.merged(world_aabb(p.volume));
    const Vec3 center = bounds.center();
    const double radius = 0.5 * (bounds.max - bounds.min).norm();
    SplitMix64 rng(regime == Regime::partial ? 99 : 199);
    std::vector<RigidTransform> poses;
    CollideResult result;
    for (int attempt = 0; attempt < 200000 && poses.size() < count; ++attempt) {
        const Mat3 rotation = rng.rotation();
        const double reach = regime == Regime::partial ? 1.0 : 2.0;
        const Vec3 offset = reach * radius * Vec3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
        const RigidTransform pose{rotation, center + offset - rotation * center};
        if (!overlaps(bvh.root().volume, transformed(bvh.root().volume, pose))) continue;
        if (regime == Regime::near) {
            collide(tree, RigidTransform::identity(), tree, pose, CollideMode::first, result);
            if (result.intersecting) continue;
        }
        poses.push_back(pose);
    }
    return poses;
}

void compare(const PairList& hbvh_pairs, const PairList& peer_pairs, const std::vector<Primitive>& primitives,
             const RigidTransform& pose, double tolerance, Agreement& agreement) {
    const auto judged_close = [&](std::pair<std::uint32_t, std::uint32_t> pair) {
        const BoundingVolume& a = primitives[pair.first].volume;
        const BoundingVolume b = transformed(primitives[pair.second].volume, pose);
        return overlaps(offset(a, tolerance), offset(b, tolerance)) !=
               overlaps(offset(a, -tolerance), offset(b, -tolerance));
    };
    std::size_t i = 0, j = 0;
    while (i < hbvh_pairs.size() || j < peer_pairs.size()) {
        if (j == peer_pairs.size() || (i < hbvh_pairs.size() && hbvh_pairs[i] < peer_pairs[j])) {
            ++(judged_close(hbvh_pairs[i]) ? agreement.close : agreement.hbvh_only);
            ++i;
        } else if (i == hbvh_pairs.size() || peer_pairs[j] < hbvh_pairs[i]) {
            ++(judged_close(peer_pairs[j]) ? agreement.close : agreement.peer_only);
            ++j;
        } else {
            ++agreement.agree;
            ++i;
            ++j;
        }
    }
}

void run_object(const Object& object, const Options& options, std::vector<Row>& rows, std::vector<BuildRow>& builds) {
    const Algorithm algorithm = pick_algorithm();
    const std::size_t n = object.primitives.size();
    const int build_repetitions = 5;
    BuildRow build_row;
    build_row.object = object.name;
    build_row.primitives = n;

    // Build times: median of a few builds each, the last one kept.
    std::vector<double> times;
    std::optional<Bvh> bvh;
    std::optional<QueryTree> tree;
    for (int r = 0; r < build_repetitions; ++r) {
        const auto start = Clock::now();
        bvh = build(object.primitives, algorithm).value();
        tree.emplace(*bvh);
        times.push_back(seconds_since(start));
        if (times.back() > 0.2) break;  // a slow build is timed once: its time is not what this table is about
    }
    build_row.hbvh_ms = 1e3 * median(times);
    build_row.hbvh_cost = cost(*bvh);
    // The speed preset: a warm-up build first (thread pool, caches), then the median of several.
    std::vector<double> fast_times;
    (void)build(object.primitives, Algorithm::fast).value();
    for (int r = 0; r < 2 * build_repetitions + 1; ++r) {
        const auto start = Clock::now();
        const Bvh fast_tree = build(object.primitives, Algorithm::fast).value();
        fast_times.push_back(seconds_since(start));
        build_row.fast_cost = cost(fast_tree);
    }
    build_row.fast_ms = 1e3 * median(fast_times);
    std::unique_ptr<Peer> bullet, fcl;
    std::vector<double> bullet_times, fcl_times;
    for (int r = 0; r < build_repetitions; ++r) {
        bullet = make_bullet_peer(object.primitives);
        bullet_times.push_back(bullet->build_seconds());
        fcl = make_fcl_peer(object.primitives);
        fcl_times.push_back(fcl->build_seconds());
    }
    build_row.bullet_ms = 1e3 * median(bullet_times);
    build_row.bullet_cost = bullet->cost();
    build_row.fcl_ms = 1e3 * median(fcl_times);
    build_row.fcl_cost = fcl->cost();
    builds.push_back(build_row);
    if (options.build_only) return;

    Aabb bounds = Aabb::empty();
    for (const Primitive& p : object.primitives) bounds = bounds.merged(world_aabb(p.volume));
    const double tolerance = options.tolerance * (bounds.max - bounds.min).norm();
    const int repetitions = n >= 1000 ? std::max(3, options.repetitions / 2) : options.repetitions;

    for (Regime regime : {Regime::partial, Regime::near, Regime::total}) {
        const std::vector<RigidTransform> poses = make_poses(*bvh, *tree, regime, options.poses);
        Row row;
        row.object = object.name;
        row.primitives = n;
        row.regime = regime;
        row.poses = poses.size();
        if (poses.empty()) {
            rows.push_back(row);
            continue;
        }
        const double count = static_cast<double>(poses.size());
        // Answers first (untimed), for the agreement check.
        CollideResult result;
        PairList peer_pairs;
        for (const RigidTransform& pose : poses) {
            collide(*tree, RigidTransform::identity(), *tree, pose, CollideMode::all, result);
            row.hbvh_pairs += result.pairs.size();
            bullet->set_pose(pose);
            bullet->collide(peer_pairs);
            compare(result.pairs, peer_pairs, object.primitives, pose, tolerance, row.bullet);
            fcl->set_pose(pose);
            fcl->collide(peer_pairs);
            compare(result.pairs, peer_pairs, object.primitives, pose, tolerance, row.fcl);
        }
        std::vector<double> hbvh_t, two_level_t, bullet_t, fcl_t, fcl_collide_t, hbvh_first_t, two_level_first_t;
        for (int r = 0; r < repetitions; ++r) {
            // Each method's timed pass follows an untimed one over the same poses, so that every method is timed
            // warm: a pass of the small objects' first-contact queries takes a few microseconds, and a few cache
            // misses left by the method timed before it (the Two-Level query's all-pairs pass sweeps the whole
            // tree) would otherwise weigh more than the query (docs/peers.md, "Warm passes").
            const auto hbvh_pass = [&](auto query, CollideMode mode) {
                for (const RigidTransform& pose : poses) query(*tree, RigidTransform::identity(), *tree, pose, mode, result);
            };
            const auto time_hbvh = [&](auto query, CollideMode mode, std::vector<double>& samples) {
                hbvh_pass(query, mode);
                const auto start = Clock::now();
                hbvh_pass(query, mode);
                samples.push_back(seconds_since(start) / count);
            };
            const auto peer_pass = [&](auto& peer) {
                for (const RigidTransform& pose : poses) {
                    peer->set_pose(pose);
                    peer->collide(peer_pairs);
                }
            };
            const auto tandem = [](const QueryTree& a, const RigidTransform& pa, const QueryTree& b,
                                   const RigidTransform& pb, CollideMode mode, CollideResult& out) {
                collide(a, pa, b, pb, mode, out);
            };
            const auto two_level = [](const QueryTree& a, const RigidTransform& pa, const QueryTree& b,
                                      const RigidTransform& pb, CollideMode mode, CollideResult& out) {
                collide_two_level(a, pa, b, pb, mode, out);
            };
            time_hbvh(tandem, CollideMode::all, hbvh_t);
            time_hbvh(two_level, CollideMode::all, two_level_t);
            time_hbvh(tandem, CollideMode::first, hbvh_first_t);
            time_hbvh(two_level, CollideMode::first, two_level_first_t);
            peer_pass(bullet);
            const auto start = Clock::now();
            peer_pass(bullet);
            bullet_t.push_back(seconds_since(start) / count);
            // FCL's pass is timed pose by pose, to tell its move from its traversal.
            peer_pass(fcl);
            double total = 0.0, collide_only = 0.0;
            for (const RigidTransform& pose : poses) {
                const auto t0 = Clock::now();
                fcl->set_pose(pose);
                const auto t1 = Clock::now();
                fcl->collide(peer_pairs);
                const auto t2 = Clock::now();
                total += std::chrono::duration<double>(t2 - t0).count();
                collide_only += std::chrono::duration<double>(t2 - t1).count();
            }
            fcl_t.push_back(total / count);
            fcl_collide_t.push_back(collide_only / count);
        }
        const auto statistic = [&](std::vector<double>& samples) {
            return 1e6 * (options.fastest ? *std::min_element(samples.begin(), samples.end()) : median(samples));
        };
        row.hbvh_us = statistic(hbvh_t);
        row.two_level_us = statistic(two_level_t);
        row.hbvh_first_us = statistic(hbvh_first_t);
        row.two_level_first_us = statistic(two_level_first_t);
        row.bullet_us = statistic(bullet_t);
        row.fcl_us = statistic(fcl_t);
        row.fcl_collide_us = statistic(fcl_collide_t);
        rows.push_back(row);
    }
}

std::string agreement_text(const Agreement& a) {
    return fmt::format("{}/{}/{}/{}", a.agree, a.peer_only, a.hbvh_only, a.close);
}

void print(const std::vector<BuildRow>& builds, const std::vector<Row>& rows, const Options& options) {
    const auto ratio = [](double peer, double ours) { return ours > 0 ? fmt::format("{:.2f}", peer / ours) : "-"; };
    if (options.markdown) {
        fmt::print("### Build\n\n| object | prims | hbvh ms | bullet ms | fcl ms | hbvh cost | bullet cost | fcl cost | "
                   "fast ms | fast cost | fast/hbvh cost | fast/bullet cost |\n");
        fmt::print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
        for (const BuildRow& b : builds)
            fmt::print("| {} | {} | {:.3f} | {:.3f} | {:.3f} | {:.4g} | {:.4g} | {:.4g} | {:.3f} | {:.4g} | {:.3f} | {:.3f} |\n",
                       b.object, b.primitives, b.hbvh_ms, b.bullet_ms, b.fcl_ms, b.hbvh_cost, b.bullet_cost, b.fcl_cost,
                       b.fast_ms, b.fast_cost, b.fast_cost / b.hbvh_cost, b.fast_cost / b.bullet_cost);
        if (options.build_only) return;
        fmt::print("\n### Query (µs per pose, {} of {} repetitions)\n\n", options.fastest ? "fastest" : "median",
                   options.repetitions);
        fmt::print("| object | prims | regime | poses | hbvh | hbvh 2-level | tandem/2-level | hbvh first | 2-level first | "
                   "tandem/2-level first | bullet | fcl | fcl collide only | bullet/hbvh | fcl/hbvh | faster peer/hbvh | "
                   "hbvh pairs | bullet =/+/-/~ | fcl =/+/-/~ |\n");
        fmt::print("|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---|\n");
        for (const Row& r : rows)
            fmt::print("| {} | {} | {} | {} | {:.2f} | {:.2f} | {} | {:.2f} | {:.2f} | {} | {:.2f} | {:.2f} | {:.2f} | {} | {} "
                       "| {} | {} | {} | {} |\n",
                       r.object, r.primitives, regime_name(r.regime), r.poses, r.hbvh_us, r.two_level_us,
                       ratio(r.hbvh_us, r.two_level_us), r.hbvh_first_us, r.two_level_first_us,
                       ratio(r.hbvh_first_us, r.two_level_first_us), r.bullet_us, r.fcl_us, r.fcl_collide_us,
                       ratio(r.bullet_us, r.hbvh_us), ratio(r.fcl_us, r.hbvh_us),
                       ratio(std::min(r.bullet_us, r.fcl_collide_us), r.hbvh_us), r.hbvh_pairs,
                       agreement_text(r.bullet), agreement_text(r.fcl));
        return;
    }
    fmt::print("{:<18} {:>6} {:>10} {:>10} {:>10} {:>11} {:>11} {:>11} {:>10} {:>11}\n", "object", "prims", "hbvh_ms",
               "bullet_ms", "fcl_ms", "hbvh_cost", "bullet_cost", "fcl_cost", "fast_ms", "fast_cost");
    for (const BuildRow& b : builds)
        fmt::print("{:<18} {:>6} {:>10.3f} {:>10.3f} {:>10.3f} {:>11.4g} {:>11.4g} {:>11.4g} {:>10.3f} {:>11.4g}\n", b.object,
                   b.primitives, b.hbvh_ms, b.bullet_ms, b.fcl_ms, b.hbvh_cost, b.bullet_cost, b.fcl_cost, b.fast_ms,
                   b.fast_cost);
    if (options.build_only) return;
    fmt::print("\n{:<18} {:>6} {:<8} {:>5} {:>9} {:>9} {:>9} {:>9} {:>9} {:>7} {:>7} {:>7}  {:<18} {:<18}\n", "object",
               "prims", "regime", "poses", "hbvh_us", "2lvl_us", "bullet_us", "fcl_us", "fclcol_us", "bt/hb",
               "fcl/hb", "pairs", "bullet =/+/-/~", "fcl =/+/-/~");
    for (const Row& r : rows)
        fmt::print("{:<18} {:>6} {:<8} {:>5} {:>9.2f} {:>9.2f} {:>9.2f} {:>9.2f} {:>9.2f} {:>7} {:>7} {:>7}  {:<18} {:<18}\n",
                   r.object, r.primitives, regime_name(r.regime), r.poses, r.hbvh_us, r.two_level_us, r.bullet_us,
                   r.fcl_us, r.fcl_collide_us, ratio(r.bullet_us, r.hbvh_us), ratio(r.fcl_us, r.hbvh_us),
                   r.hbvh_pairs, agreement_text(r.bullet), agreement_text(r.fcl));
}

}  // namespace
}  // namespace hbvh::peers

int main(int argc, char** argv) {
    using namespace hbvh::peers;
    Options options;
    for (int i = 1; i < argc; ++i) {
        const std::string_view arg = argv[i];
        if (arg == "--markdown") {
            options.markdown = true;
        } else if (arg == "--poses" && i + 1 < argc) {
            options.poses = std::strtoul(argv[++i], nullptr, 10);
        } else if (arg == "--repetitions" && i + 1 < argc) {
            options.repetitions = std::atoi(argv[++i]);
        } else if (arg == "--fastest") {
            options.fastest = true;
        } else if (arg == "--build-only") {
            options.build_only = true;
        } else if (arg == "--only" && i + 1 < argc) {
            options.only = argv[++i];
        } else {
            fmt::print(stderr, "usage: hbvh_peers [--markdown] [--poses N] [--repetitions N] [--only NAME] [--fastest] [--build-only]\n");
            return 2;
        }
    }
    std::vector<Row> rows;
    std::vector<BuildRow> builds;
    fmt::print(stderr, "hbvh_peers: builder {}\n", hbvh::to_string(pick_algorithm()));
    for (const Object& object : hbvh::bench::load_bench_objects("hbvh_peers"))
        if (object.name.find(options.only) != std::string::npos) run_object(object, options, rows, builds);
    print(builds, rows, options);
    // A disagreement beyond the tolerance means one of the three is wrong: fail, so that scripts notice.
    std::uint64_t disagreements = 0;
    for (const Row& row : rows)
        disagreements += row.bullet.peer_only + row.bullet.hbvh_only + row.fcl.peer_only + row.fcl.hbvh_only;
    if (disagreements > 0) {
        fmt::print(stderr, "hbvh_peers: {} pair disagreements beyond the tolerance\n", disagreements);
        return 1;
    }
    return 0;
}
