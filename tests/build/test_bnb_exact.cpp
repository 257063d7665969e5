// SPDX-License-Identifier: MIT
// bnb-exact: valid trees, never worse than bnb-enlarge on generated scenes and the bundled models.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "hbvh/build/bnb_exact.hpp"
#include "hbvh/build/build.hpp"
#include "hbvh/io/xml.hpp"
#include "hbvh/scene/generate.hpp"
#include "hbvh/tree/stats.hpp"
#include "hbvh/tree/validate.hpp"

namespace hbvh {
namespace {

void expect_no_worse_than_enlarge(const std::vector<Primitive>& primitives, const std::string& what) {
    BuildOptions options;
    BuildReport report;
    options.report = &report;
    const Result<Bvh> exact = build(primitives, Algorithm::bnb_exact, options);
    options.report = nullptr;
    const Result<Bvh> enlarge = build(primitives, Algorithm::bnb_enlarge, options);
    ASSERT_TRUE(exact.has_value() && enlarge.has_value()) << what;
    EXPECT_TRUE(validate(*exact).has_value()) << what;
    EXPECT_LE(cost(*exact), cost(*enlarge)) << what;
    EXPECT_FALSE(report.levels.empty()) << what;

}

TEST(BnbExact, IsRegistered) { EXPECT_EQ(parse_algorithm("bnb-exact"), Algorithm::bnb_exact); }

TEST(BnbExact, NoWorseThanEnlargeOnGeneratedScenes) {
    for (std::uint32_t count : {9u, 16u}) {
        SceneOptions scene;
        scene.count = count;
        scene.seed = 100 + count;
        expect_no_worse_than_enlarge(generate_scene(scene), "scene" + std::to_string(count));
    }
}

TEST(BnbExact, NoWorseThanEnlargeOnBundledModels) {
    const std::filesystem::path models = std::filesystem::path(HBVH_SOURCE_DIR) / "data" / "models";
    if (!std::filesystem::exists(models)) GTEST_SKIP() << "no data/models";
    for (const auto& entry : std::filesystem::directory_iterator(models)) {
        if (entry.path().extension() != ".xml") continue;
        const Result<XmlModel> model = read_xml_file(entry.path());
        ASSERT_TRUE(model.has_value()) << entry.path();
        expect_no_worse_than_enlarge(model->primitives, entry.path().stem().string());
    }
}

}  // namespace
}  // namespace hbvh
