// SPDX-License-Identifier: MIT
// The collision simulator of the survey's §5.3: velocity projection on contact, timing only the queries
// whose roots overlap so that every measured query really descends the hierarchy.
#include "hbvh/query/simulate.hpp"

#include <algorithm>
#include <chrono>
#include <limits>

#include "hbvh/assert.hpp"
#include "hbvh/scene/generate.hpp"

namespace hbvh {
namespace {

/// Running sums behind a QueryStats.
struct Accumulator {
    std::uint32_t queries = 0, intersecting = 0;
    double seconds = 0.0, bv_tests = 0.0, primitive_tests = 0.0, nodes_visited = 0.0;

    void add(const CollideResult& r, double elapsed) {
        ++queries;
        intersecting += r.intersecting ? 1 : 0;
        seconds += elapsed;
        bv_tests += static_cast<double>(r.bv_tests);
        primitive_tests += static_cast<double>(r.primitive_tests);
        nodes_visited += static_cast<double>(r.nodes_visited);
    }
    [[nodiscard]] QueryStats stats() const {
        QueryStats s;
        s.queries = queries;
        s.intersecting = intersecting;
        if (queries == 0) return s;
        const double n = queries;
        s.mean_query_ms = 1e3 * seconds / n;
        s.mean_bv_tests = bv_tests / n;
        s.mean_primitive_tests = primitive_tests / n;
        s.mean_nodes_visited = nodes_visited / n;
        return s;
    }
};

/// One query of the simulator's method and mode.
void run_query(const QueryTree& a, const RigidTransform& pose_a, const QueryTree& b, const RigidTransform& pose_b,
               const SimulateOptions& options, CollideResult& result) {
    if (options.method == QueryMethod::tandem)
        collide(a, pose_a, b, pose_b, options.mode, result);
    else
        collide_two_level(a, pose_a, b, pose_b, options.mode, result);
}

/// One timed query; only the query call is inside the clock.
double timed_query(const QueryTree& tree, const RigidTransform& pose_a, const RigidTransform& pose_b,
                   const SimulateOptions& options, CollideResult& result) {
    const auto start = std::chrono::steady_clock::now();
    run_query(tree, pose_a, tree, pose_b, options, result);
    const auto stop = std::chrono::steady_clock::now();
    return std::chrono::duration<double>(stop - start).count();
}

/// Pose that puts the object's model-frame point `center` at `position` with orientation `rotation`.
RigidTransform placed(const Mat3& rotation, const Vec3& position, const Vec3& center) {
    return {rotation, position - rotation * center};
}

}  // namespace

SimulationResult simulate(const Bvh& object, const SimulateOptions& options) {
    HBVH_ASSERT(!object.empty());
    SimulationResult out;
    const QueryTree tree(object);
    Aabb bounds = Aabb::empty();
    for (const Primitive& p : object.primitives) bounds = bounds.merged(world_aabb(p.volume));
    const Vec3 center = bounds.center();
    const double radius = std::max(0.5 * (bounds.max - bounds.min).norm(), 1e-12);
    const double speed = options.step * radius;
    const RigidTransform pose_a = RigidTransform::identity();

    SplitMix64 rng(options.seed);
    CollideResult result;
    Accumulator moving;

    // State of the mover B: centre position, orientation, velocity (per step).
    Vec3 position, velocity;
    Mat3 rotation;
    int blocked = 0;
    const auto launch = [&] {
        const Vec3 direction = rng.rotation().col(0);
        position = center + 2.5 * radius * direction;
        rotation = rng.rotation();
        const Vec3 target = center + 0.5 * radius * Vec3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
        velocity = speed * (target - position).normalized();
        blocked = 0;
    };
    launch();

    while (moving.queries < options.collision_count && out.steps < options.max_steps) {
        ++out.steps;
        const Vec3 next = position + velocity;
        const RigidTransform pose_b = placed(rotation, next, center);
        const double elapsed = timed_query(tree, pose_a, pose_b, options, result);
        // The root test is always the first test, and only a pair of overlapping roots gets visited.
        if (result.nodes_visited > 0) {
            moving.add(result, elapsed);
            if (options.record_poses) out.moving_poses.push_back(pose_b);
        }
        if (!result.intersecting) {
            position = next;
            blocked = 0;
        } else {
            // Contact: stay, and remove the velocity component pointing into the contact. The direction
            // joins the first reported primitive pair's centres (from A's primitive towards B's).
            const auto [ia, ib] = result.pairs.front();
            const Vec3 ca = pose_a.apply(world_aabb(object.primitives[ia].volume).center());
            const Vec3 cb = pose_b.apply(world_aabb(object.primitives[ib].volume).center());
            Vec3 normal = cb - ca;
            if (normal.squaredNorm() < 1e-24 * radius * radius) normal = next - center;
            if (normal.squaredNorm() < 1e-24 * radius * radius) normal = -velocity;
            normal.normalize();
            const double into = velocity.dot(normal);
            if (into < 0.0) velocity -= into * normal;
            ++blocked;
        }
        // Re-launch when B has left, nearly stopped, or is wedged.
        if ((position - center).norm() > 3.0 * radius || velocity.norm() < 0.01 * speed || blocked > 20) {
            launch();
            ++out.restarts;
        }
    }
    out.moving = moving.stats();
    out.complete = moving.queries >= options.collision_count;

    // Totally colliding: one copy placed on the other (identical random poses), the survey's last column.
    Accumulator total;
    for (std::uint32_t k = 0; k < options.collision_count; ++k) {
        const RigidTransform pose = placed(rng.rotation(), center, center);
        const double elapsed = timed_query(tree, pose, pose, options, result);
        total.add(result, elapsed);
        if (options.record_poses) out.total_poses.push_back(pose);
    }
    out.total = total.stats();
    return out;
}

double time_queries(const QueryTree& tree, std::span<const RigidTransform> poses, SimulatedPhase phase,
                    QueryMethod method, CollideMode mode, int passes) {
    return time_queries(tree, tree, poses, phase, method, mode, passes);
}

double time_queries(const QueryTree& a, const QueryTree& b, std::span<const RigidTransform> poses,
                    SimulatedPhase phase, QueryMethod method, CollideMode mode, int passes) {
    HBVH_ASSERT(!poses.empty() && passes >= 1);
    const SimulateOptions options{.method = method, .mode = mode};
    const RigidTransform identity = RigidTransform::identity();
    CollideResult result;
    double fastest = std::numeric_limits<double>::infinity();
    for (int pass = 0; pass < passes; ++pass) {
        const auto start = std::chrono::steady_clock::now();
        for (const RigidTransform& pose : poses) {
            const RigidTransform& pose_a = phase == SimulatedPhase::moving ? identity : pose;
            run_query(a, pose_a, b, pose, options, result);
        }
        const auto stop = std::chrono::steady_clock::now();
        fastest = std::min(fastest, std::chrono::duration<double>(stop - start).count());
    }
    return fastest / static_cast<double>(poses.size());
}

}  // namespace hbvh
