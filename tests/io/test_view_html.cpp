// SPDX-License-Identifier: MIT
// export_html(): one offline page whose embedded JSON holds every level and every BV.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "hbvh/io/level_view.hpp"
#include "hbvh/io/view_html.hpp"
#include "io/sample_hierarchy.hpp"

namespace hbvh {
namespace {

using nlohmann::json;

json embedded_data(const std::string& page) {
    const std::string open = "<script type=\"application/json\" id=\"hbvh-data\">";
    const std::size_t begin = page.find(open);
    EXPECT_NE(begin, std::string::npos);
    const std::size_t end = page.find("</script>", begin);
    return json::parse(page.substr(begin + open.size(), end - begin - open.size()));
}

TEST(ExportHtml, IsSelfContained) {
    const std::string page = export_html(test::sample_hierarchy(), "sample");
    EXPECT_EQ(page.rfind("<!DOCTYPE html>", 0), 0u);
    EXPECT_EQ(page.find("http://"), std::string::npos);
    EXPECT_EQ(page.find("https://"), std::string::npos);
    EXPECT_EQ(page.find("<script src"), std::string::npos);
    EXPECT_EQ(page.find("<link"), std::string::npos);
    EXPECT_NE(page.find("<canvas"), std::string::npos);
    EXPECT_NE(page.find("type=\"range\""), std::string::npos);
}

TEST(ExportHtml, EmbedsLevelsStatisticsAndMeshes) {
    const Bvh bvh = test::sample_hierarchy();
    const json data = embedded_data(export_html(bvh, "sample"));
    const std::vector<LevelView> views = level_views(bvh);
    ASSERT_EQ(data["levels"].size(), views.size());
    for (std::size_t d = 0; d < views.size(); ++d) {
        EXPECT_EQ(data["levels"][d]["nodes"].get<std::vector<std::uint32_t>>(), views[d].nodes);
        EXPECT_EQ(data["levels"][d]["carried"].get<std::vector<std::uint32_t>>(), views[d].carried);
        EXPECT_DOUBLE_EQ(data["levels"][d]["cost"].get<double>(), views[d].cost);
        EXPECT_DOUBLE_EQ(data["levels"][d]["volume"].get<double>(), views[d].volume);
    }
    ASSERT_EQ(data["bvs"].size(), bvh.nodes.size());
    // Dequantised vertices stay within one quantum of the BV's world AABB.
    const double quantum = data["quantum"];
    for (std::size_t n = 0; n < bvh.nodes.size(); ++n) {
        const Aabb box = world_aabb(bvh.nodes[n].volume);
        const std::vector<double> p = data["bvs"][n]["p"].get<std::vector<double>>();
        ASSERT_EQ(p.size() % 3, 0u);
        for (std::size_t i = 0; i < p.size(); ++i) {
            const double value = data["origin"][i % 3].get<double>() + p[i] * quantum;
            EXPECT_GE(value, box.min[static_cast<Eigen::Index>(i % 3)] - quantum);
            EXPECT_LE(value, box.max[static_cast<Eigen::Index>(i % 3)] + quantum);
        }
    }
    EXPECT_EQ(data["bvs"][bvh.nodes.size() - 1]["leaf"], true);
}

TEST(ExportHtml, EscapesTitleAndNames) {
    Bvh bvh = test::sample_hierarchy();
    bvh.primitives[4].name = "</script><script>alert(1)</script>";
    const std::string page = export_html(bvh, "<b>chair</b> & co");
    EXPECT_NE(page.find("<title>&lt;b&gt;chair&lt;/b&gt; &amp; co</title>"), std::string::npos);
    EXPECT_EQ(page.find("alert(1)</script>"), std::string::npos);
    const json data = embedded_data(page);
    EXPECT_EQ(data["title"], "<b>chair</b> & co");
    bool found = false;
    for (const json& bv : data["bvs"])
        if (bv.contains("name") && bv["name"] == bvh.primitives[4].name) found = true;
    EXPECT_TRUE(found);
}

TEST(ExportHtml, EmptyHierarchyStillMakesAPage) {
    const json data = embedded_data(export_html(Bvh{}, "empty"));
    EXPECT_TRUE(data["levels"].empty());
}

}  // namespace
}  // namespace hbvh
