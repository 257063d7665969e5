// SPDX-License-Identifier: MIT
// export_dot(): labels, carried copies, escaping, and that Graphviz accepts the output.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "hbvh/io/export_dot.hpp"
#include "io/sample_hierarchy.hpp"

namespace hbvh {
namespace {

std::size_t count(const std::string& text, const std::string& needle) {
    std::size_t n = 0;
    for (std::size_t at = text.find(needle); at != std::string::npos; at = text.find(needle, at + 1)) ++n;
    return n;
}

TEST(ExportDot, LabelsInnerNodesAndLeaves) {
    const std::string dot = export_dot(test::sample_hierarchy());
    EXPECT_EQ(dot.rfind("digraph hbvh {", 0), 0u);
    EXPECT_NE(dot.find("aabb\\nV = "), std::string::npos);
    EXPECT_NE(dot.find("2 children"), std::string::npos);
    EXPECT_NE(dot.find("3 children"), std::string::npos);
    EXPECT_NE(dot.find("#4 knob\\nsphere"), std::string::npos);
    EXPECT_NE(dot.find("#2\\nsphere"), std::string::npos);  // unnamed primitive: index only
    EXPECT_NE(dot.find("height 3"), std::string::npos);
}

TEST(ExportDot, CarriesHighLeavesDownToTheBottomRow) {
    // Leaf 'knob' hangs at depth 1, the lone sphere at depth 2; the bottom is depth 3:
    // grey copies at depths 1, 2 for the knob and at 2 for the sphere.
    const std::string dot = export_dot(test::sample_hierarchy());
    EXPECT_EQ(count(dot, "style=\"rounded,filled,dashed\""), 3u);
    const std::string plain = export_dot(test::sample_hierarchy(), {.carry_leaves = false});
    EXPECT_EQ(count(plain, "dashed"), 0u);
    // 7 edges in the tree; each copy adds one.
    EXPECT_EQ(count(plain, " -> "), 7u);
    EXPECT_EQ(count(dot, " -> "), 10u);
}

TEST(ExportDot, EscapesNames) {
    Bvh bvh = test::sample_hierarchy();
    bvh.primitives[4].name = "say \"hi\"\\";
    const std::string dot = export_dot(bvh);
    EXPECT_NE(dot.find("say \\\"hi\\\"\\\\"), std::string::npos);
}

TEST(ExportDot, EmptyHierarchyIsAnEmptyGraph) { EXPECT_EQ(export_dot(Bvh{}), "digraph hbvh {\n}\n"); }

TEST(ExportDot, GraphvizAcceptsIt) {
    if (std::system("dot -V > /dev/null 2>&1") != 0) GTEST_SKIP() << "graphviz is not installed";
    // Per process: other checkouts may run the same test at the same time.
    const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / ("hbvh_dot_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    Bvh bvh = test::sample_hierarchy();
    bvh.primitives[4].name = "odd \"name\" \\ here";
    std::ofstream(dir / "tree.dot") << export_dot(bvh);
    const std::string command = "dot -Tsvg '" + (dir / "tree.dot").string() + "' -o '" + (dir / "tree.svg").string() +
                                "' 2> '" + (dir / "dot.log").string() + "'";
    ASSERT_EQ(std::system(command.c_str()), 0);
    std::ifstream in(dir / "tree.svg");
    const std::string svg((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(svg.find("<svg"), std::string::npos);
    EXPECT_NE(svg.find("#4 odd"), std::string::npos);
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace hbvh
