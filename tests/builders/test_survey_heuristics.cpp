// SPDX-License-Identifier: MIT
// The survey's heuristic builders (§2.1-2.3) through build(): shared properties, order (in)dependence.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "hbvh/builders/auto.hpp"
#include "hbvh/builders/build.hpp"
#include "hbvh/builders/insertion.hpp"
#include "hbvh/builders/insertion_haber.hpp"
#include "hbvh/io/xml.hpp"
#include "hbvh/scene/generate.hpp"
#include "hbvh/tree/stats.hpp"
#include "hbvh/tree/validate.hpp"
#include "support/test_helpers.hpp"
#include "support/tree_properties.hpp"


namespace hbvh {
namespace {

constexpr Algorithm heuristic_builders[] = {Algorithm::merge, Algorithm::insertion, Algorithm::insertion_haber,
                                            Algorithm::split, Algorithm::obb_tree};
constexpr Algorithm order_independent_builders[] = {Algorithm::merge, Algorithm::split, Algorithm::obb_tree};
constexpr Algorithm order_dependent_builders[] = {Algorithm::insertion, Algorithm::insertion_haber};

// The shared property check: every primitive in exactly one leaf, leaves carry their primitive, no inner
// node with one child, every node's BV contains the generating spheres of every covered primitive
// (relative tolerance 1e-9 of the node's size), and validate() agrees. Returns the built hierarchy.
Bvh check_properties(const std::vector<Primitive>& primitives, Algorithm algorithm, const BuildContext& options = {}) {
    SCOPED_TRACE(std::string(to_string(algorithm)) + " over " + std::to_string(primitives.size()) + " primitives");
    Result<Bvh> built = build(primitives, algorithm, options);
    EXPECT_TRUE(built.has_value()) << (built.has_value() ? "" : built.error().to_string());
    if (!built.has_value()) return {};
    const Bvh& bvh = built.value();
    test_support::expect_tree_properties(primitives, bvh);
    return bvh;
}

using test_support::expect_identical_trees;
using test_support::generated_scene;
using test_support::shuffled;

double cost_of(const std::vector<Primitive>& primitives, Algorithm algorithm) {
    Result<Bvh> built = build(primitives, algorithm);
    EXPECT_TRUE(built.has_value());
    return built.has_value() ? cost(built.value()) : -1.0;
}

// One test per builder, so each stays short and a failure names its builder.
class EveryHeuristic : public testing::TestWithParam<Algorithm> {};

// Every size up to 32 (the small objects, where the degenerate groupings are), then a sample up to 60, both
// sides of 48. Every size up to 60 took 37 s for insertion-haber under the sanitizers, a twelfth of the suite's
// time on two cores.
TEST_P(EveryHeuristic, PropertiesOnGeneratedScenesOfEverySize) {
    std::vector<std::uint32_t> counts;
    for (std::uint32_t count = 1; count <= 32; ++count) counts.push_back(count);
    counts.insert(counts.end(), {40, 47, 48, 60});
    for (const std::uint32_t count : counts) check_properties(generated_scene(count, 1000 + count, count % 2 == 0), GetParam());
}

INSTANTIATE_TEST_SUITE_P(SurveyHeuristics, EveryHeuristic, testing::ValuesIn(heuristic_builders),
                         [](const testing::TestParamInfo<Algorithm>& param) {
                             std::string name(to_string(param.param));
                             std::replace(name.begin(), name.end(), '-', '_');
                             return name;
                         });

TEST(SurveyHeuristics, PropertiesUnderRestrictedPolicies) {
    const std::vector<Primitive> primitives = generated_scene(40, 7);
    for (const BvType only : all_bv_types) {
        BuildContext options;
        options.policy = VolumePolicy::only(only);
        for (const Algorithm algorithm : heuristic_builders) {
            const Bvh bvh = check_properties(primitives, algorithm, options);
            for (const Node& node : bvh.nodes) {
                if (!node.is_leaf()) {
                    EXPECT_EQ(type_of(node.volume), only);
                }
            }
        }
    }
}

TEST(SurveyHeuristics, DegenerateInputs) {
    // Identical primitives and coincident points: every split and every enlargement degenerates.
    std::vector<Primitive> same(9, Primitive{Sphere{Vec3(1, 2, 3), 0.5}, ""});
    std::vector<Primitive> points(7, Primitive{Sphere{Vec3::Zero(), 0.0}, ""});
    points[3].volume = Sphere{Vec3(5, 0, 0), 0.0};
    for (const Algorithm algorithm : heuristic_builders) {
        check_properties(same, algorithm);
        check_properties(points, algorithm);
        EXPECT_FALSE(build(std::vector<Primitive>{}, algorithm).has_value());
    }
}

TEST(SurveyHeuristics, MergeBranchingFactorIsAnOption) {
    const std::vector<Primitive> primitives = generated_scene(50, 11);
    for (const std::uint32_t factor : {2u, 3u, 4u, 8u}) {
        MergeOptions options;
        options.branching_factor = factor;
        const Result<Bvh> built = build_merge(primitives, BuildContext{}, options);
        ASSERT_TRUE(built.has_value()) << factor;
        test_support::expect_tree_properties(primitives, *built);
        // Groups get factor to 2 x factor - 2 children (merge.hpp).
        for (const Node& node : built->nodes) EXPECT_LE(node.child_count, std::max(2u, 2 * factor - 2)) << factor;
    }
}

TEST(SurveyHeuristics, CostIsIndependentOfInputOrder) {
    for (const Algorithm algorithm : order_independent_builders)
        for (const std::uint32_t count : {2u, 7u, 25u, 60u}) {
            const std::vector<Primitive> primitives = generated_scene(count, 77 + count, count % 2 == 1);
            const double reference = cost_of(primitives, algorithm);
            for (std::uint64_t shuffle = 1; shuffle <= 4; ++shuffle) {
                const double c = cost_of(shuffled(primitives, shuffle), algorithm);
                EXPECT_NEAR(c, reference, 1e-9 * std::abs(reference))
                    << to_string(algorithm) << ", " << count << " primitives, shuffle " << shuffle;
            }
        }
}

/// Inner nodes of `bvh` over more than `count` primitives.
int nodes_over(const Bvh& bvh, std::uint32_t count) {
    std::vector<std::uint32_t> below(bvh.nodes.size(), 0);
    int over = 0;
    // Breadth-first order: every child comes after its parent, so a backward sweep sees children first.
    for (std::size_t i = bvh.nodes.size(); i-- > 0;) {
        const Node& node = bvh.nodes[i];
        if (node.is_leaf()) {
            below[i] = 1;
            continue;
        }
        for (std::uint32_t c = node.first_child; c < node.first_child + node.child_count; ++c) below[i] += below[c];
        if (below[i] > count) ++over;
    }
    return over;
}

// split plans the two halves of every cut in parallel; the tree must not depend on the thread count. Halves
// go to TBB above 256 primitives (split.cpp): this scene's cuts 1000 -> 537 + 463 -> ... take that path four
// times, three deep. (3000 primitives took it fifteen times, for three times the time: 29-38 s under the
// sanitizers.)
TEST(SurveyHeuristics, SplitSameTreeForOneAndTwoThreads) {
    const std::vector<Primitive> primitives = generated_scene(1000, 43);
    const auto build_with = [&](std::size_t threads) {
        const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
        Result<Bvh> built = build(primitives, Algorithm::split);
        EXPECT_TRUE(built.has_value());
        return built.has_value() ? std::move(built.value()) : Bvh{};
    };
    const Bvh one = build_with(1);
    EXPECT_GE(nodes_over(one, 256), 3) << "too few cuts take the parallel path to compare thread counts";
    expect_identical_trees(one, build_with(2));
}

TEST(SurveyHeuristics, InsertionDependsOnInputOrder) {
    // The survey's complaint about insertion (§2.1): some shuffle of this scene changes the hierarchy.
    const std::vector<Primitive> primitives = generated_scene(30, 5);
    for (const Algorithm algorithm : order_dependent_builders) {
        const double reference = cost_of(primitives, algorithm);
        bool changed = false;
        for (std::uint64_t shuffle = 1; shuffle <= 8 && !changed; ++shuffle)
            changed = std::abs(cost_of(shuffled(primitives, shuffle), algorithm) - reference) > 1e-9 * reference;
        EXPECT_TRUE(changed) << to_string(algorithm);
    }
}

TEST(SurveyHeuristics, AutosRefitCapStopsAChainAndSparesOrdinaryInput) {
    // A rope of 200 capsules in order: each new one lies beyond every group, the insertion grows a chain, and its
    // exact refits fit every ancestor again (cubic in n). Under auto's cap both insertions give up...
    std::vector<Primitive> rope;
    for (int i = 0; i < 200; ++i)
        rope.push_back(Primitive{Capsule{Vec3(i - 0.4, 0.0, 0.0), Vec3(i + 0.4, 0.0, 0.0), 0.1}, ""});
    const std::uint64_t cap = auto_insertion_refit_budget(rope.size());
    const auto gives_up = [](const std::vector<Primitive>& primitives, Algorithm algorithm, std::uint64_t budget) {
        BuildReport report;
        BuildContext context;
        context.report = &report;
        InsertionOptions insertion;
        insertion.max_refit_primitives = budget;
        InsertionHaberOptions haber;
        haber.max_refit_primitives = budget;
        const Result<Bvh> built = algorithm == Algorithm::insertion ? build_insertion(primitives, context, insertion)
                                                                    : build_insertion_haber(primitives, context, haber);
        EXPECT_TRUE(built.has_value());
        if (built) test_support::expect_tree_properties(primitives, *built);
        return report.budget_hit;
    };
    for (const Algorithm algorithm : order_dependent_builders) EXPECT_TRUE(gives_up(rope, algorithm, cap)) << to_string(algorithm);
    // ... and shuffled, the same rope stays within it, as do generated scenes of every size auto gives the
    // insertions (11-200) and the bundled models: there the cap changes no tree.
    std::vector<std::vector<Primitive>> ordinary{shuffled(rope, 1)};
    for (const std::uint32_t count : {11u, 24u, 25u, 54u, 100u, 200u})
        for (const std::uint64_t seed : {1u, 2u}) ordinary.push_back(generated_scene(count, seed, seed == 1));
    for (const auto& file : {"cannon.xml", "chair.xml", "helicopter.xml", "tie_interceptor.xml"}) {
        Result<XmlModel> model = read_xml_file(std::filesystem::path(HBVH_SOURCE_DIR) / "data" / "models" / file);
        ASSERT_TRUE(model.has_value()) << file;
        ordinary.push_back(model->primitives);
    }
    for (const auto& primitives : ordinary)
        for (const Algorithm algorithm : order_dependent_builders)
            EXPECT_FALSE(gives_up(primitives, algorithm, auto_insertion_refit_budget(primitives.size())))
                << to_string(algorithm) << " on " << primitives.size() << " primitives";
}

/// The *.xml files of `folder`, sorted.
std::vector<std::filesystem::path> xml_files(const std::filesystem::path& folder) {
    std::vector<std::filesystem::path> files;
    std::error_code error;
    for (const auto& entry : std::filesystem::directory_iterator(folder, error))
        if (entry.path().extension() == ".xml") files.push_back(entry.path());
    std::sort(files.begin(), files.end());
    return files;
}

TEST(SurveyHeuristics, BundledModels) {
    // Shipped with the repository: a missing or unreadable model is a failure.
    const std::filesystem::path folder = std::filesystem::path(HBVH_SOURCE_DIR) / "data" / "models";
    ASSERT_TRUE(std::filesystem::is_directory(folder)) << "missing bundled models: " << folder;
    const auto files = xml_files(folder);
    ASSERT_FALSE(files.empty()) << "no *.xml in " << folder;
    for (const auto& file : files) {
        Result<XmlModel> model = read_xml_file(file);
        ASSERT_TRUE(model.has_value()) << file << ": " << model.error().to_string();
        SCOPED_TRACE(file.filename().string());
        for (const Algorithm algorithm : heuristic_builders) check_properties(model->primitives, algorithm);
    }
}

TEST(SurveyHeuristics, SharedModels) {
    // ../shared is optional and also holds MJCF files: skip, saying why, when it has no hbvh model.
    const std::filesystem::path folder = std::filesystem::path(HBVH_SHARED_DIR) / "data" / "models";
    if (!std::filesystem::is_directory(folder)) GTEST_SKIP() << "no shared models at " << folder;
    int checked = 0;
    for (const auto& file : xml_files(folder)) {
        Result<XmlModel> model = read_xml_file(file);
        if (!model.has_value()) continue;  // not an hbvh model file (other formats share the folder)
        SCOPED_TRACE(file.filename().string());
        for (const Algorithm algorithm : heuristic_builders) check_properties(model->primitives, algorithm);
        ++checked;
    }
    if (checked == 0) GTEST_SKIP() << "no hbvh model file among the *.xml in " << folder;
}

}  // namespace
}  // namespace hbvh
