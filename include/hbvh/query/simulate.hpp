// SPDX-License-Identifier: MIT
// The survey's collision benchmark (§5.3, Table 4): two copies of one object, one sliding into the
// other with velocity projection, timing the queries in which the root volumes overlap.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "hbvh/query/tandem_traversal.hpp"

namespace hbvh {

/// Which query the simulator times.
enum class QueryMethod : std::uint8_t {
    tandem,     ///< collide(): tandem traversal of the hierarchy.
    two_level,  ///< collide_two_level(): root test, then every primitive pair (the survey's baseline).
};

/// Knobs of simulate(); the defaults reproduce the survey's setting (1000 root-overlapping queries).
struct SimulateOptions {
    std::uint32_t collision_count = 1000;  ///< Queries with overlapping roots to measure (the survey's 1000).
    std::uint64_t seed = 1;                ///< Start states and restarts; same seed, same run (timings aside).
    QueryMethod method = QueryMethod::tandem;
    CollideMode mode = CollideMode::first;  ///< `first` answers "do they collide", as a simulator asks.
    double step = 0.05;                    ///< Distance moved per step, as a fraction of the object's radius.
    std::uint64_t max_steps = 2'000'000;   ///< Gives up (complete = false) after this many steps.
    /// Keep the measured queries' poses (SimulationResult::moving_poses, total_poses), so that other trees
    /// over the same primitives can be timed on exactly these queries (time_queries).
    bool record_poses = false;
};

/// Averages over a set of timed queries.
struct QueryStats {
    std::uint32_t queries = 0;        ///< Queries measured.
    std::uint32_t intersecting = 0;   ///< Of those, how many found overlapping primitives.
    double mean_query_ms = 0.0;       ///< Wall time per query (steady_clock around the query call only).
    double mean_bv_tests = 0.0;
    double mean_primitive_tests = 0.0;
    double mean_nodes_visited = 0.0;
};

/// What simulate() measured.
struct SimulationResult {
    /// The moving case: the first `collision_count` queries whose root BVs overlapped.
    QueryStats moving;
    /// "Totally colliding": `collision_count` queries with both copies at the same (random) pose.
    QueryStats total;
    std::uint64_t steps = 0;     ///< Simulation steps taken (queries run, measured or not).
    std::uint32_t restarts = 0;  ///< Times the mover was re-launched (left the scene or got stuck).
    bool complete = false;       ///< False when max_steps ran out before collision_count samples.
    /// With record_poses: copy B's pose in each measured moving query (copy A rests at the identity).
    std::vector<RigidTransform> moving_poses;
    /// With record_poses: the shared pose of both copies in each totally colliding query.
    std::vector<RigidTransform> total_poses;
};

/// Runs the simulator on two copies of `object` (non-empty). Copy A rests at the identity pose. Copy B,
/// randomly oriented, starts 2.5 radii from A's centre and moves straight at `step` radii per step towards
/// a point near A's centre. When a step would make the copies collide, B stays put and its velocity loses
/// the component pointing into the contact; the contact direction is the line between the world centres
/// of the first reported primitive pair's BVs (objects' centres if those coincide). B is re-launched from a
/// new seeded start when it gets 3 radii away, slows below 1% of its speed, or stays blocked 20 steps.
/// Frames: the object's model frame; its radius is half the diagonal of its primitives' AABB.
[[nodiscard]] SimulationResult simulate(const Bvh& object, const SimulateOptions& options = {});

/// Which of the simulator's query sets time_queries replays.
enum class SimulatedPhase : std::uint8_t {
    moving,  ///< Copy A at the identity, copy B at each pose.
    total,   ///< Both copies at each pose.
};

/// Mean seconds per query of `method` on two copies of `tree` over `poses` (as recorded by simulate for
/// `phase`): the fastest of `passes` passes, each timed as a whole. Unlike simulate's own per-query clock,
/// this is fit to rank trees: every tree answers the same queries, no clock call sits inside a query, and
/// the fastest pass drops what other processes cost. Precondition: poses non-empty, passes >= 1.
[[nodiscard]] double time_queries(const QueryTree& tree, std::span<const RigidTransform> poses, SimulatedPhase phase,
                                  QueryMethod method, CollideMode mode, int passes);
/// The same with two different trees over the same poses: `a` as copy A, `b` as copy B (each tree's primitives
/// in its own frame; `hbvh calibrate` times trees of different BV kinds against each other this way).
[[nodiscard]] double time_queries(const QueryTree& a, const QueryTree& b, std::span<const RigidTransform> poses,
                                  SimulatedPhase phase, QueryMethod method, CollideMode mode, int passes);

}  // namespace hbvh
