// SPDX-License-Identifier: MIT
// bnb-exact's own search, with the bnb-enlarge safety net off: on every level, no costlier than the level
// bnb-enlarge would pick on the same nodes, and equal to an exhaustive enumeration of set partitions on
// small levels. Then the safety net: the registered builder returns the cheaper of the two trees.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "builders/bottom_up.hpp"
#include "builders/candidates.hpp"
#include "builders/rich_candidates.hpp"
#include "builders/set_partition.hpp"
#include "hbvh/builders/bnb_exact.hpp"
#include "hbvh/builders/build.hpp"
#include "hbvh/io/xml.hpp"
#include "hbvh/scene/generate.hpp"
#include "hbvh/tree/stats.hpp"
#include "hbvh/tree/validate.hpp"
#include "support/bundled_models.hpp"
#include "support/test_helpers.hpp"

namespace hbvh {
namespace {

/// Levels up to this size are also solved by exhaustive enumeration (its work grows like 2^n per state).
constexpr std::uint32_t exhaustive_max_nodes = 14;

/// What one level of an instrumented bnb-exact build saw.
struct LevelRecord {
    std::uint32_t nodes = 0;
    std::optional<double> exact_cost;       ///< The cover solve_exact gave the driver on the first call.
    bool exact_proven = false;              ///< That call finished (no budget stop).
    bool fallback_used = false;             ///< The driver had to call the solver again.
    std::optional<double> enlarge_cost;     ///< The cover bnb-enlarge's solver picks on these very nodes.
    bool enlarge_fallback = false;          ///< Enlarge's candidates admitted no cover: fallback sets added.
    std::vector<std::vector<std::uint32_t>> enlarge_sets;  ///< Every set bnb-enlarge's solver could choose.
    std::vector<Candidate> rich_sets;       ///< bnb-exact's candidates, normalised and priced.
    std::optional<double> exhaustive_cost;  ///< The cheapest partition into rich candidates, by enumeration.
};

/// Cheapest total cost over every set partition of the nodes in `uncovered` (a bitmask) whose blocks all
/// appear in `block_costs`, by plain enumeration: the block holding the lowest uncovered node runs over
/// every subset of the uncovered nodes. No bound, no ordering: nothing shared with the library's solvers.
double cheapest_partition(std::uint32_t uncovered, const std::map<std::uint32_t, double>& block_costs) {
    if (uncovered == 0) return 0.0;
    const std::uint32_t lowest = uncovered & (~uncovered + 1u);
    const std::uint32_t others = uncovered ^ lowest;
    double best = std::numeric_limits<double>::infinity();
    // Every subset `rest` of `others`, the empty one included (which makes a singleton: never a candidate).
    for (std::uint32_t rest = others;; rest = (rest - 1u) & others) {
        const auto block = block_costs.find(lowest | rest);
        if (block != block_costs.end())
            best = std::min(best, block->second + cheapest_partition(others & ~rest, block_costs));
        if (rest == 0) break;
    }
    return best;
}

/// The exhaustive optimum of a level of `node_count` (< 32) nodes whose candidates are `candidates` (+inf
/// when none covers it).
double exhaustive_optimum(std::uint32_t node_count, std::span<const Candidate> candidates) {
    std::map<std::uint32_t, double> block_costs;
    for (const Candidate& candidate : candidates) {
        std::uint32_t mask = 0;
        for (std::uint32_t member : candidate.members) mask |= 1u << member;
        block_costs[mask] = candidate.cost;
    }
    return cheapest_partition((1u << node_count) - 1u, block_costs);
}

/// bnb-exact without guarantee_enlarge, rebuilt from its parts (rich candidates, solve_exact, the bottom-up
/// driver) so that every level can be looked at; `records` gets one entry per level.
Bvh build_instrumented(const std::vector<Primitive>& primitives, const VolumePolicy& policy,
                       std::vector<LevelRecord>& records) {
    const BnbExactOptions exact_options;
    const BnbEnlargeOptions enlarge_options;
    auto generate = [&](const Level& level) {
        LevelRecord record;
        record.nodes = level.size();
        // What bnb-enlarge's driver does on this level: its candidates, priced the same way, its solver,
        // and, when they admit no cover, the same again with the fallback sets added.
        std::vector<std::vector<std::uint32_t>> enlarge_sets = enlarge_candidates(level, enlarge_options.enlarge);
        std::vector<double> volumes;
        for (const LevelNode& node : level.nodes()) volumes.push_back(node.weighted_volume);
        std::vector<Candidate> enlarge = make_candidates(level, enlarge_sets);
        const SolverBudget& budget = enlarge_options.budget;
        std::optional<Partition> picked = solve_reference_branch_and_bound(level.size(), enlarge, volumes, budget);
        if (!picked) {
            record.enlarge_fallback = true;
            for (std::vector<std::uint32_t>& set : fallback_member_sets(level)) enlarge_sets.push_back(std::move(set));
            enlarge = make_candidates(level, enlarge_sets);
            picked = solve_reference_branch_and_bound(level.size(), enlarge, volumes, budget);
        }
        if (picked) record.enlarge_cost = picked->cost;
        record.enlarge_sets = std::move(enlarge_sets);
        std::vector<std::vector<std::uint32_t>> rich = rich_candidates(level, exact_options.nearest_neighbours);
        record.rich_sets = make_candidates(level, rich);
        if (level.size() <= exhaustive_max_nodes) {
            const double optimum = exhaustive_optimum(level.size(), record.rich_sets);
            if (std::isfinite(optimum)) record.exhaustive_cost = optimum;
        }
        records.push_back(std::move(record));
        return rich;
    };
    auto solve = [&](std::uint32_t node_count, std::span<const Candidate> candidates, std::span<const double>,
                     const SolverBudget& budget) {
        std::optional<Partition> partition = solve_exact(node_count, candidates, budget);
        LevelRecord& record = records.back();
        // Only the first call of a level is the search the claims are about; a second one means the
        // first found no cover and the driver added its fallback sets.
        if (partition && !record.exact_cost && !record.fallback_used) {
            record.exact_cost = partition->cost;
            record.exact_proven = !partition->budget_hit;
        } else {
            record.fallback_used = true;
        }
        return partition;
    };
    return build_bottom_up(primitives, policy, generate, solve, {exact_options.budget, nullptr});
}

/// The per-level claims of docs/solver.md §3 on one input, with the safety net off. Returns the number of
/// levels compared with bnb-enlarge's choice.
int expect_exact_levels(const std::vector<Primitive>& primitives, const std::string& what) {
    const VolumePolicy policy = VolumePolicy::all();
    std::vector<LevelRecord> records;
    const Bvh instrumented = build_instrumented(primitives, policy, records);
    BnbExactOptions no_net;
    no_net.guarantee_enlarge = false;
    const Bvh exact_alone = build_bnb_exact(primitives, test_support::context_for(policy), no_net).value();
    // The instrumented build is the library's bnb-exact search, not a look-alike.
    EXPECT_EQ(cost(instrumented, policy), cost(exact_alone, policy)) << what;
    const Status valid = validate(exact_alone);
    EXPECT_TRUE(valid.has_value()) << what << ": " << (valid.has_value() ? "" : valid.error().to_string());

    int enlarge_compared = 0;
    for (std::size_t i = 0; i < records.size(); ++i) {
        const LevelRecord& level = records[i];
        const std::string where = what + " level " + std::to_string(i) + " (" + std::to_string(level.nodes) + " nodes)";
        // Tightest's growth from any node reaches the whole level, so the rich candidates always admit a
        // cover and the driver never needs its fallback; a budget stop would void the optimality.
        if (!level.exact_cost || level.fallback_used) {
            ADD_FAILURE() << where << ": solve_exact found no cover among the rich candidates";
            continue;
        }
        EXPECT_TRUE(level.exact_proven) << where;
        // The rich candidates contain Enlarge's, and the fallback sets (each node's first two Tightest
        // growth steps) are among Tightest's, which the rich candidates contain too. Checked first, since
        // the claim below rests on it.
        std::vector<std::vector<std::uint32_t>> rich;
        for (const Candidate& candidate : level.rich_sets) rich.push_back(candidate.members);
        std::sort(rich.begin(), rich.end());
        for (std::vector<std::uint32_t> set : level.enlarge_sets) {
            std::sort(set.begin(), set.end());
            set.erase(std::unique(set.begin(), set.end()), set.end());
            if (set.size() >= 2) {
                EXPECT_TRUE(std::binary_search(rich.begin(), rich.end(), set)) << where;
            }
        }
        // solve_exact is exact over the rich candidates, so the level's cover costs no more than any cover
        // of bnb-enlarge's candidates, in particular the one its solver picks. (When even the fallback sets
        // admit no cover, bnb-enlarge's driver builds a greedy cover of non-candidate groups: no claim.)
        if (level.enlarge_cost) {
            EXPECT_LE(*level.exact_cost, *level.enlarge_cost * (1.0 + 1e-12))
                << where << (level.enlarge_fallback ? " (Enlarge with fallback sets)" : "");
            ++enlarge_compared;
        }
        if (level.nodes <= exhaustive_max_nodes) {
            EXPECT_TRUE(level.exhaustive_cost.has_value()) << where;
        }
        if (level.exhaustive_cost) {
            EXPECT_NEAR(*level.exact_cost, *level.exhaustive_cost, 1e-9 * *level.exhaustive_cost) << where;
        }
    }
    return enlarge_compared;
}

/// The safety net: the registered builder returns exactly the cheaper of bnb-exact's own tree and
/// bnb-enlarge's. Returns whether bnb-enlarge's was the cheaper.
bool expect_cheaper_of_both(const std::vector<Primitive>& primitives, const std::string& what) {
    BuildReport report;
    BuildContext context;
    context.report = &report;
    const Result<Bvh> chosen = build(primitives, Algorithm::bnb_exact, context);
    context.report = nullptr;
    const Result<Bvh> enlarge = build(primitives, Algorithm::bnb_enlarge, context);
    BnbExactOptions no_net;
    no_net.guarantee_enlarge = false;
    const Bvh exact_alone = build_bnb_exact(primitives, context, no_net).value();
    if (!chosen.has_value() || !enlarge.has_value()) {
        ADD_FAILURE() << what << ": a build failed";
        return false;
    }
    EXPECT_TRUE(validate(*chosen).has_value()) << what;
    EXPECT_EQ(cost(*chosen), std::min(cost(exact_alone), cost(*enlarge))) << what;
    EXPECT_FALSE(report.levels.empty()) << what;
    return cost(*enlarge) < cost(exact_alone);
}

std::vector<std::pair<std::string, std::vector<Primitive>>> generated_scenes() {
    std::vector<std::pair<std::string, std::vector<Primitive>>> scenes;
    for (std::uint32_t count : {5u, 9u, 12u, 16u}) {
        for (std::uint64_t seed : {1u, 2u}) {
            SceneOptions scene;
            scene.count = count;
            scene.seed = 100 * seed + count;
            scenes.emplace_back("scene " + std::to_string(count) + " seed " + std::to_string(scene.seed),
                                generate_scene(scene));
        }
    }
    return scenes;
}

TEST(BnbExact, IsRegistered) { EXPECT_EQ(parse_algorithm("bnb-exact"), Algorithm::bnb_exact); }

TEST(BnbExact, ExhaustiveEnumerationCountsEveryPartition) {
    // The oracle itself: with every subset of size >= 2 as a block of cost 1, the optimum is the fewest
    // blocks (1, the whole set); with cost = size^2, all pairs (and one triple for odd n) win.
    for (std::uint32_t n : {2u, 3u, 6u, 7u}) {
        std::vector<Candidate> unit, square;
        for (std::uint32_t mask = 1; mask < (1u << n); ++mask) {
            if (std::popcount(mask) < 2) continue;
            std::vector<std::uint32_t> members;
            for (std::uint32_t j = 0; j < n; ++j)
                if (mask & (1u << j)) members.push_back(j);
            const double size = static_cast<double>(members.size());
            unit.push_back({members, 1.0});
            square.push_back({members, size * size});
        }
        EXPECT_EQ(exhaustive_optimum(n, unit), 1.0) << n;
        EXPECT_EQ(exhaustive_optimum(n, square), n % 2 == 0 ? 2.0 * n : 2.0 * (n - 3) + 9.0) << n;
    }
    EXPECT_EQ(exhaustive_optimum(3, std::vector<Candidate>{{{0, 1}, 1.0}}), std::numeric_limits<double>::infinity());
}

TEST(BnbExact, EachLevelOptimalAndNoCostlierThanEnlargesOnGeneratedScenes) {
    int compared = 0;
    for (const auto& [name, primitives] : generated_scenes()) compared += expect_exact_levels(primitives, name);
    EXPECT_GE(compared, 10);  // most levels have a cover among bnb-enlarge's candidates
}

TEST(BnbExact, EachLevelOptimalAndNoCostlierThanEnlargesOnBundledModels) {
    // The bundled models up to 17 primitives (chair, helicopter, cannon). The tie interceptor's 27 make the same
    // claims on larger levels, but its two builds were three quarters of this test's 30-39 s under the sanitizers,
    // and the generated scenes and these three already make every claim (bnb-exact's tree of it is still built and
    // checked, through `stats`, by the Python suite's test_cost_and_stats_equal_the_cli).
    int compared = 0;
    for (const auto& [name, primitives] : test_support::bundled_models()) {
        if (primitives.size() > 17) continue;
        compared += expect_exact_levels(primitives, name);
    }
    EXPECT_GE(compared, 5);
}

TEST(BnbExact, ReturnsTheCheaperOfItsOwnTreeAndEnlarges) {
    int enlarge_cheaper = 0;
    for (const auto& [name, primitives] : generated_scenes())
        enlarge_cheaper += expect_cheaper_of_both(primitives, name) ? 1 : 0;
    // The chair: the bundled model on which bnb-exact's own tree costs more (docs/solver.md §3), so that
    // the net's other branch is taken too.
    const std::filesystem::path chair = std::filesystem::path(HBVH_SOURCE_DIR) / "data" / "models" / "chair.xml";
    const Result<XmlModel> model = read_xml_file(chair);
    ASSERT_TRUE(model.has_value()) << chair << ": " << model.error().to_string();
    enlarge_cheaper += expect_cheaper_of_both(model->primitives, "chair") ? 1 : 0;
    EXPECT_GT(enlarge_cheaper, 0);
}

}  // namespace
}  // namespace hbvh
