// SPDX-License-Identifier: MIT
// TreeAssembler layout, level views, validate() and the survey's cost on hand-computed examples.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include <unistd.h>

#include <filesystem>
#include <numbers>
#include <string>

#include "hbvh/files.hpp"
#include "hbvh/fit/volume_policy.hpp"
#include "hbvh/tree/bvh.hpp"
#include "hbvh/tree/stats.hpp"
#include "hbvh/tree/validate.hpp"

namespace hbvh {
namespace {

Primitive unit_box_at(double x) { return {Aabb{Vec3(x, 0, 0), Vec3(x + 1, 1, 1)}, "box"}; }

/// Four unit boxes on the x axis at 0, 2, 4, 6, grouped ((0,1),(2,3)).
Bvh two_pairs() {
    std::vector<Primitive> primitives{unit_box_at(0), unit_box_at(2), unit_box_at(4), unit_box_at(6)};
    TreeAssembler assembler(primitives);
    std::uint32_t leaves[4];
    for (std::uint32_t i = 0; i < 4; ++i) leaves[i] = assembler.add_leaf(i);
    const std::uint32_t left[] = {leaves[0], leaves[1]};
    const std::uint32_t right[] = {leaves[2], leaves[3]};
    const std::uint32_t a = assembler.add_group(left, Aabb{Vec3(0, 0, 0), Vec3(3, 1, 1)});
    const std::uint32_t b = assembler.add_group(right, Aabb{Vec3(4, 0, 0), Vec3(7, 1, 1)});
    const std::uint32_t groups[] = {a, b};
    const std::uint32_t root = assembler.add_group(groups, Aabb{Vec3(0, 0, 0), Vec3(7, 1, 1)});
    return std::move(assembler).finish(root);
}

TEST(TreeAssembler, LaysOutBreadthFirstWithContiguousChildren) {
    const Bvh bvh = two_pairs();
    ASSERT_EQ(bvh.nodes.size(), 7u);
    EXPECT_EQ(bvh.root().child_count, 2u);
    EXPECT_EQ(bvh.root().first_child, 1u);
    EXPECT_EQ(bvh.nodes[1].first_child, 3u);
    EXPECT_EQ(bvh.nodes[2].first_child, 5u);
    const auto level_view = levels(bvh);
    ASSERT_EQ(level_view.size(), 3u);
    EXPECT_EQ(level_view[1], (std::vector<std::uint32_t>{1, 2}));
    EXPECT_EQ(level_view[2].size(), 4u);
    EXPECT_EQ(covered_primitives(bvh, 2), (std::vector<std::uint32_t>{2, 3}));
    // No such node covers nothing (it read past the array and crashed).
    EXPECT_TRUE(covered_primitives(bvh, static_cast<std::uint32_t>(bvh.nodes.size())).empty());
    EXPECT_TRUE(covered_primitives(bvh, 1000).empty());
    EXPECT_TRUE(validate(bvh).has_value());
}

TEST(TreeAssembler, CollapsesSingleChildChains) {
    std::vector<Primitive> primitives{unit_box_at(0), unit_box_at(2)};
    TreeAssembler assembler(primitives);
    const std::uint32_t a = assembler.add_leaf(0);
    const std::uint32_t b = assembler.add_leaf(1);
    const std::uint32_t only_b[] = {b};
    const std::uint32_t wrapper = assembler.add_group(only_b, Aabb{Vec3(2, 0, 0), Vec3(3, 1, 1)});
    const std::uint32_t pair[] = {a, wrapper};
    const std::uint32_t root = assembler.add_group(pair, Aabb{Vec3(0, 0, 0), Vec3(3, 1, 1)});
    const std::uint32_t only_root[] = {root};
    const Bvh bvh = std::move(assembler).finish(assembler.add_group(only_root, Aabb{Vec3(0, 0, 0), Vec3(3, 1, 1)}));
    ASSERT_EQ(bvh.nodes.size(), 3u);
    EXPECT_TRUE(bvh.nodes[1].is_leaf());
    EXPECT_TRUE(bvh.nodes[2].is_leaf());
    EXPECT_TRUE(validate(bvh).has_value());
}

/// A balanced tree over `count` unit boxes, pairs grouped level by level; `reserved` items reserved first.
Bvh paired_tree(std::uint32_t count, std::size_t reserved, std::vector<std::uint32_t>* id_of_node) {
    std::vector<Primitive> primitives;
    for (std::uint32_t i = 0; i < count; ++i) primitives.push_back(unit_box_at(2.0 * i));
    TreeAssembler assembler(primitives);
    if (reserved > 0) assembler.reserve(reserved);
    std::vector<std::uint32_t> level;
    for (std::uint32_t i = 0; i < count; ++i) level.push_back(assembler.add_leaf(i));
    std::vector<double> low(count), high(count);
    for (std::uint32_t i = 0; i < count; ++i) low[i] = 2.0 * i, high[i] = 2.0 * i + 1;
    while (level.size() > 1) {
        std::vector<std::uint32_t> next;
        std::vector<double> next_low, next_high;
        for (std::size_t i = 0; i < level.size(); i += 2) {
            if (i + 1 == level.size()) {
                next.push_back(level[i]), next_low.push_back(low[i]), next_high.push_back(high[i]);
                continue;
            }
            const std::uint32_t pair[] = {level[i], level[i + 1]};
            next.push_back(assembler.add_group(pair, Aabb{Vec3(low[i], 0, 0), Vec3(high[i + 1], 1, 1)}));
            next_low.push_back(low[i]), next_high.push_back(high[i + 1]);
        }
        level = std::move(next), low = std::move(next_low), high = std::move(next_high);
    }
    return std::move(assembler).finish(level.front(), id_of_node);
}

TEST(TreeAssembler, ReservingChangesNothingButCapacity) {
    // 30 000 leaves: the items (about 5 MB) and the nodes are past the size at which they go on huge pages.
    std::vector<std::uint32_t> plain_ids, reserved_ids, short_ids;
    const Bvh plain = paired_tree(30000, 0, &plain_ids);
    const Bvh reserved = paired_tree(30000, 60000, &reserved_ids);
    const Bvh short_reserve = paired_tree(30000, 10, &short_ids);  // too little: the arrays grow as usual
    ASSERT_TRUE(validate(plain).has_value());
    ASSERT_EQ(plain.nodes.size(), 59999u);
    for (const Bvh* other : {&reserved, &short_reserve}) {
        ASSERT_EQ(other->nodes.size(), plain.nodes.size());
        for (std::size_t i = 0; i < plain.nodes.size(); ++i) {
            ASSERT_EQ(other->nodes[i].first_child, plain.nodes[i].first_child) << i;
            ASSERT_EQ(other->nodes[i].child_count, plain.nodes[i].child_count) << i;
            ASSERT_EQ(other->nodes[i].primitive, plain.nodes[i].primitive) << i;
            ASSERT_EQ(std::get<Aabb>(other->nodes[i].volume).min, std::get<Aabb>(plain.nodes[i].volume).min) << i;
            ASSERT_EQ(std::get<Aabb>(other->nodes[i].volume).max, std::get<Aabb>(plain.nodes[i].volume).max) << i;
        }
    }
    EXPECT_EQ(reserved_ids, plain_ids);
    EXPECT_EQ(short_ids, plain_ids);
    EXPECT_EQ(cost(reserved), cost(plain));
}

TEST(Validate, RejectsABvThatMissesAPrimitive) {
    Bvh bvh = two_pairs();
    bvh.nodes[1].volume = Aabb{Vec3(0, 0, 0), Vec3(2.5, 1, 1)};  // misses the second box's far half
    const Status status = validate(bvh);
    ASSERT_FALSE(status.has_value());
    EXPECT_NE(status.error().message.find("node 1"), std::string::npos);
}

TEST(Validate, RejectsDuplicateAndMissingPrimitives) {
    Bvh bvh = two_pairs();
    bvh.nodes[6].primitive = 0;
    EXPECT_FALSE(validate(bvh).has_value());
}

TEST(Validate, RejectsSingleChildInnerNodes) {
    Bvh bvh = two_pairs();
    bvh.nodes[0].child_count = 1;
    EXPECT_FALSE(validate(bvh).has_value());
}

TEST(Stats, CostIsChildrenTimesVolumeSummedOverInnerNodes) {
    // Hand computation: root 2 children x 7 + two groups 2 x 3 each = 14 + 12 = 26.
    const Bvh bvh = two_pairs();
    EXPECT_DOUBLE_EQ(cost(bvh), 26.0);
    const Stats stats = compute_stats(bvh);
    EXPECT_DOUBLE_EQ(stats.cost, 26.0);
    EXPECT_EQ(stats.height, 2u);
    EXPECT_EQ(stats.inner_nodes, 3u);
    EXPECT_EQ(stats.leaves, 4u);
    EXPECT_DOUBLE_EQ(stats.branching.mean, 2.0);
    // Tightness: root 7 / (3 + 3); groups 3 / (1 + 1).
    EXPECT_DOUBLE_EQ(stats.tightness.min, 7.0 / 6.0);
    EXPECT_DOUBLE_EQ(stats.tightness.max, 1.5);
    EXPECT_DOUBLE_EQ(stats.leaf_depth.mean, 2.0);
    EXPECT_DOUBLE_EQ(stats.overlap, 0.0);  // siblings are disjoint (they touch nowhere)
    EXPECT_EQ(stats.types[0], 7u);
}

// Eq. 1 over children without volume: a box over two flat plates is infinitely loose (such nodes were left out, and
// a tree of only them read 0, "perfectly tight"); a tree whose every volume is 0 has no ratio at all (NaN).
TEST(Stats, TightnessOverChildrenWithoutVolumeIsInfiniteOrUndefined) {
    const std::vector<Primitive> plates{{Aabb{Vec3(0, 0, 0), Vec3(1, 1, 0)}, ""}, {Aabb{Vec3(0, 0, 1), Vec3(1, 1, 1)}, ""}};
    TreeAssembler over_plates(plates);
    const std::uint32_t plate_leaves[] = {over_plates.add_leaf(0), over_plates.add_leaf(1)};
    const Stats loose = compute_stats(std::move(over_plates).finish(
        over_plates.add_group(plate_leaves, Aabb{Vec3(0, 0, 0), Vec3(1, 1, 1)})));
    EXPECT_EQ(loose.tightness.min, std::numeric_limits<double>::infinity());
    EXPECT_EQ(loose.tightness.max, std::numeric_limits<double>::infinity());
    // With a finite ratio beside it, the finite one is the minimum.
    const Stats mixed = compute_stats(two_pairs());
    EXPECT_TRUE(std::isfinite(mixed.tightness.max));
    const std::vector<Primitive> lines{{Aabb{Vec3(0, 0, 0), Vec3(1, 0, 0)}, ""}, {Aabb{Vec3(2, 0, 0), Vec3(3, 0, 0)}, ""}};
    TreeAssembler over_lines(lines);
    const std::uint32_t line_leaves[] = {over_lines.add_leaf(0), over_lines.add_leaf(1)};
    const Stats flat = compute_stats(std::move(over_lines).finish(
        over_lines.add_group(line_leaves, Aabb{Vec3(0, 0, 0), Vec3(3, 0, 0)})));
    EXPECT_TRUE(std::isnan(flat.tightness.min) && std::isnan(flat.tightness.mean) && std::isnan(flat.tightness.max));
}

TEST(Stats, WeightsScaleEachTypesVolume) {
    VolumePolicy policy;
    policy.weight[static_cast<std::size_t>(BvType::aabb)] = 2.0;
    EXPECT_DOUBLE_EQ(cost(two_pairs(), policy), 52.0);
}

TEST(Stats, OverlapMeasuresSiblingAabbIntersection) {
    std::vector<Primitive> primitives{{Aabb{Vec3(0, 0, 0), Vec3(2, 1, 1)}, ""}, {Aabb{Vec3(1, 0, 0), Vec3(3, 1, 1)}, ""}};
    TreeAssembler assembler(primitives);
    const std::uint32_t leaves[] = {assembler.add_leaf(0), assembler.add_leaf(1)};
    const Bvh bvh = std::move(assembler).finish(assembler.add_group(leaves, Aabb{Vec3(0, 0, 0), Vec3(3, 1, 1)}));
    // Intersection 1 over sibling volume 2 + 2.
    EXPECT_DOUBLE_EQ(compute_stats(bvh).overlap, 0.25);
}

TEST(BoundingVolume, CapsuleVolumeIsCylinderPlusBall) {
    const Capsule capsule{Vec3(0, 0, 0), Vec3(0, 0, 2), 0.5};
    EXPECT_DOUBLE_EQ(capsule.volume(), std::numbers::pi * 0.25 * 2 + 4.0 / 3.0 * std::numbers::pi * 0.125);
}

TEST(BoundingVolume, TransformedAabbIsExactObb) {
    const BoundingVolume box = Aabb{Vec3(0, 0, 0), Vec3(1, 2, 3)};
    RigidTransform t;
    t.rotation = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
    t.translation = Vec3(5, -1, 2);
    const BoundingVolume moved = transformed(box, t);
    EXPECT_NEAR(volume(moved), 6.0, 1e-12);
    for (const Sphere& corner : generating_spheres(box)) EXPECT_TRUE(contains(moved, corner.transformed(t), 1e-12));
}

TEST(VolumePolicy, ParsesTypesAndWeights) {
    const Result<VolumePolicy> types = parse_allowed_types("aabb, sphere");
    ASSERT_TRUE(types.has_value());
    EXPECT_TRUE(types->is_allowed(BvType::aabb));
    EXPECT_FALSE(types->is_allowed(BvType::obb));
    EXPECT_FALSE(parse_allowed_types("aabb,cone").has_value());
    EXPECT_FALSE(parse_allowed_types("").has_value());
    const Result<VolumePolicy> weights = parse_type_weights("obb=1.5,capsule=1.2");
    ASSERT_TRUE(weights.has_value());
    EXPECT_DOUBLE_EQ(weights->weight_of(BvType::obb), 1.5);
    EXPECT_FALSE(parse_type_weights("obb=0").has_value());
    EXPECT_FALSE(parse_type_weights("obb=nan").has_value());
    EXPECT_FALSE(parse_type_weights("obb").has_value());
    // Weights are ratios of test costs: far outside [1e-6, 1e6] they only overflow or underflow the cost.
    EXPECT_TRUE(parse_type_weights("obb=1e-6,capsule=1e6").has_value());
    EXPECT_FALSE(parse_type_weights("obb=1e308").has_value());
    EXPECT_FALSE(parse_type_weights("obb=1e-320").has_value());
    EXPECT_FALSE(parse_type_weights("obb=9.9e-7").has_value());
    // A kind weighted twice is refused: which weight was meant cannot be told.
    const Result<VolumePolicy> twice = parse_type_weights("obb=1,sphere=2,obb=2");
    ASSERT_FALSE(twice.has_value());
    EXPECT_NE(twice.error().message.find("obb is weighted twice"), std::string::npos) << twice.error().message;
}

// The file `hbvh calibrate -o` writes: its table of pairs as '#' comments, then the weights; entries may also come
// one per line or separated by ", " as an editor leaves them. A bad entry is named with its file and line.
TEST(VolumePolicy, ReadsTheCalibratedWeightsFileAndNamesTheLineOfABadEntry) {
    const std::filesystem::path path =
        std::filesystem::temp_directory_path() / ("hbvh_weights_" + std::to_string(::getpid()) + ".txt");
    const auto read = [&](const std::string& text) {
        EXPECT_TRUE(write_file_atomic(path, text).has_value());
        return read_type_weights_file(path);
    };
    const Result<VolumePolicy> calibrated = read(
        "# hbvh calibrate: ns per inner-node test\n#          aabb   obb=9\n# aabb    19.5  24.0\n"
        "aabb=1.000,obb=1.275,sphere=0.384,capsule=1.258\n");
    ASSERT_TRUE(calibrated.has_value()) << calibrated.error().to_string();
    EXPECT_DOUBLE_EQ(calibrated->weight_of(BvType::obb), 1.275);  // not the 9 in the comment
    EXPECT_DOUBLE_EQ(calibrated->weight_of(BvType::sphere), 0.384);
    const Result<VolumePolicy> edited = read("obb=1.5, capsule=1.2   # heavier\n\nsphere=0.5\n");
    ASSERT_TRUE(edited.has_value()) << edited.error().to_string();
    EXPECT_DOUBLE_EQ(edited->weight_of(BvType::capsule), 1.2);
    EXPECT_DOUBLE_EQ(edited->weight_of(BvType::sphere), 0.5);
    EXPECT_DOUBLE_EQ(edited->weight_of(BvType::aabb), 1.0);
    const Result<VolumePolicy> bad = read("# weights\naabb=1\nobb=heavy\n");
    ASSERT_FALSE(bad.has_value());
    EXPECT_EQ(bad.error().line, 3);
    EXPECT_EQ(bad.error().file, path.string());
    EXPECT_NE(bad.error().message.find("obb=heavy"), std::string::npos);
    const Result<VolumePolicy> repeated = read("aabb=1\nobb=2\naabb=3\n");  // also across lines
    ASSERT_FALSE(repeated.has_value());
    EXPECT_EQ(repeated.error().line, 3);
    EXPECT_NE(repeated.error().message.find("aabb is weighted twice"), std::string::npos);
    const Result<VolumePolicy> comments_only = read("# nothing measured\n");
    EXPECT_FALSE(comments_only.has_value());
    std::filesystem::remove(path);
    EXPECT_FALSE(read_type_weights_file(path).has_value());  // and a missing file is an error, not the defaults
}

}  // namespace
}  // namespace hbvh
