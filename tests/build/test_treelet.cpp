// SPDX-License-Identifier: MIT
// Treelet refinement: never costlier, valid trees, exactly optimal when one treelet spans the input,
// deterministic for any thread count; and `auto` (portfolio + refinement) no worse than its members.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "hbvh/build/build.hpp"
#include "hbvh/build/treelet.hpp"
#include "hbvh/io/xml.hpp"
#include "hbvh/scene/generate.hpp"
#include "hbvh/tree/stats.hpp"
#include "hbvh/tree/validate.hpp"
#include "support/tree_properties.hpp"

namespace hbvh {
namespace {

using test_support::generated_scene;

std::vector<std::pair<std::string, std::vector<Primitive>>> bundled_models() {
    std::vector<std::pair<std::string, std::vector<Primitive>>> models;
    const std::filesystem::path folder = std::filesystem::path(HBVH_SOURCE_DIR) / "data" / "models";
    if (!std::filesystem::exists(folder)) return models;
    for (const auto& entry : std::filesystem::directory_iterator(folder)) {
        if (entry.path().extension() != ".xml") continue;
        Result<XmlModel> model = read_xml_file(entry.path());
        if (model.has_value()) models.emplace_back(entry.path().stem().string(), std::move(model->primitives));
    }
    std::sort(models.begin(), models.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    return models;
}

Bvh build_with(const std::vector<Primitive>& primitives, Algorithm algorithm) {
    Result<Bvh> built = build(primitives, algorithm, {});
    EXPECT_TRUE(built.has_value());
    return built.has_value() ? std::move(built.value()) : Bvh{};
}

// validate() (containment of every covered primitive, each primitive once, no single-child node), and the
// refined cost no higher than the input's (summation order may differ: 1e-12 relative).
void expect_refined_well(const Bvh& input, const Bvh& refined, const TreeletReport& report, const std::string& what) {
    const Status valid = validate(refined);
    EXPECT_TRUE(valid.has_value()) << what << ": " << (valid.has_value() ? "" : valid.error().to_string());
    const double before = cost(input);
    const double after = cost(refined);
    EXPECT_LE(after, before * (1.0 + 1e-12)) << what;
    EXPECT_DOUBLE_EQ(report.cost_before, before) << what;
    EXPECT_DOUBLE_EQ(report.cost_after, after) << what;
    EXPECT_EQ(refined.primitives.size(), input.primitives.size()) << what;
}

TEST(Treelet, NeverCostlierOnBundledModels) {
    const auto models = bundled_models();
    if (models.empty()) GTEST_SKIP() << "no data/models";
    for (const auto& [name, primitives] : models) {
        for (Algorithm algorithm : {Algorithm::two_level, Algorithm::split, Algorithm::insertion, Algorithm::merge}) {
            const Bvh input = build_with(primitives, algorithm);
            TreeletReport report;
            const Bvh refined = refine_treelets(input, VolumePolicy::all(), {}, &report);
            expect_refined_well(input, refined, report, name + " / " + std::string(to_string(algorithm)));
            EXPECT_GE(report.passes, 1u);
        }
    }
}

TEST(Treelet, NeverCostlierOnGeneratedScenes) {
    TreeletOptions options;
    options.max_units = 5;
    for (std::uint32_t count : {2u, 3u, 30u, 70u}) {
        const std::vector<Primitive> primitives = generated_scene(count, 7 + count);
        for (Algorithm algorithm : {Algorithm::split, Algorithm::insertion, Algorithm::scale}) {
            const Bvh input = build_with(primitives, algorithm);
            TreeletReport report;
            const Bvh refined = refine_treelets(input, VolumePolicy::all(), options, &report);
            expect_refined_well(input, refined, report,
                                "scene " + std::to_string(count) + " / " + std::string(to_string(algorithm)));
        }
    }
}

TEST(Treelet, RespectsThePolicy) {
    const std::vector<Primitive> primitives = generated_scene(20, 3);
    VolumePolicy spheres_only = VolumePolicy::only(BvType::sphere);
    BuildOptions options;
    options.policy = spheres_only;
    Result<Bvh> built = build(primitives, Algorithm::split, options);
    ASSERT_TRUE(built.has_value());
    TreeletReport report;
    const Bvh refined = refine_treelets(*built, spheres_only, {}, &report);
    EXPECT_TRUE(validate(refined).has_value());
    EXPECT_LE(cost(refined, spheres_only), cost(*built, spheres_only) * (1.0 + 1e-12));
    for (const Node& node : refined.nodes) {
        if (!node.is_leaf()) {
            EXPECT_EQ(type_of(node.volume), BvType::sphere);
        }
    }
}

// With max_units >= n the root's treelet spans every primitive, so its DP is build_optimal's DP on the
// same fits: the result is the optimum (an independent check of the refiner's bookkeeping).
TEST(Treelet, OneTreeletOverEverythingIsOptimal) {
    TreeletOptions options;
    options.max_units = 8;
    for (std::uint32_t count : {3u, 5u, 8u}) {
        const std::vector<Primitive> primitives = generated_scene(count, 40 + count);
        const double optimum = cost(build_with(primitives, Algorithm::optimal));
        for (Algorithm algorithm : {Algorithm::two_level, Algorithm::split, Algorithm::insertion, Algorithm::merge}) {
            const Bvh refined = refine_treelets(build_with(primitives, algorithm), VolumePolicy::all(), options);
            const std::string what = "n=" + std::to_string(count) + " / " + std::string(to_string(algorithm));
            EXPECT_TRUE(validate(refined).has_value()) << what;
            EXPECT_NEAR(cost(refined) / optimum, 1.0, 1e-9) << what;
        }
    }
}

TEST(Treelet, SameTreeForAnyThreadCount) {
    const std::vector<Primitive> primitives = generated_scene(40, 11);
    const Bvh input = build_with(primitives, Algorithm::split);
    auto refine_with = [&](int threads) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
        return refine_treelets(input, VolumePolicy::all());
    };
    const Bvh one = refine_with(1);
    const Bvh two = refine_with(2);
    ASSERT_EQ(one.nodes.size(), two.nodes.size());
    for (std::size_t i = 0; i < one.nodes.size(); ++i) {
        EXPECT_EQ(one.nodes[i].child_count, two.nodes[i].child_count) << i;
        EXPECT_EQ(one.nodes[i].first_child, two.nodes[i].first_child) << i;
        EXPECT_EQ(one.nodes[i].primitive, two.nodes[i].primitive) << i;
        EXPECT_EQ(volume(one.nodes[i].volume), volume(two.nodes[i].volume)) << i;
    }
    EXPECT_EQ(cost(one), cost(two));
}

TEST(Treelet, RefineOptionAppliesToAnyBuilder) {
    const std::vector<Primitive> primitives = generated_scene(25, 5);
    BuildOptions options;
    BuildReport report;
    options.refine = true;
    options.treelets.max_units = 5;
    options.report = &report;
    Result<Bvh> refined = build(primitives, Algorithm::insertion, options);
    ASSERT_TRUE(refined.has_value());
    EXPECT_TRUE(validate(*refined).has_value());
    EXPECT_LE(cost(*refined), cost(build_with(primitives, Algorithm::insertion)) * (1.0 + 1e-12));
    ASSERT_FALSE(report.notes.empty());
    EXPECT_TRUE(report.notes.back().starts_with("treelets:")) << report.notes.back();
}

TEST(Auto, NoCostlierThanAnyPortfolioMemberOnBundledModels) {
    const auto models = bundled_models();
    if (models.empty()) GTEST_SKIP() << "no data/models";
    for (const auto& [name, primitives] : models) {
        const double chosen = cost(build_with(primitives, Algorithm::automatic));
        for (Algorithm member : auto_portfolio(primitives.size()))
            EXPECT_LE(chosen, cost(build_with(primitives, member)) * (1.0 + 1e-12))
                << name << " / " << to_string(member);
    }
}

}  // namespace
}  // namespace hbvh
