// SPDX-License-Identifier: MIT
// The speed anchor for large scenes: Embree's rtcBuildBVH (binned SAH, binary AABB nodes, one primitive
// per leaf, two threads) over the primitives' world AABBs, side by side with hbvh's split and scale limited
// to AABBs, on the `hbvh generate --seed 1` scenes of 20 000 and 10^6 primitives. Embree's tree is measured
// with the same Eq. 2 cost: sum over inner nodes of child count x volume of the node's AABB, each node's box
// recomputed in double as the union of its primitives' world boxes (Embree's own bounds are floats).
// Built only when CMake finds Embree (bench/CMakeLists.txt).
//
//   hbvh_bench --benchmark_filter='embree_anchor/20k'    (seconds; prints a table)
//   hbvh_bench --benchmark_filter='embree_anchor/1M$'    (minutes: split and scale at 10^6)
//   hbvh_bench --benchmark_filter='embree_anchor/1M_binned'  (binned alone: seconds)
#include <benchmark/benchmark.h>
#include <embree3/rtcore.h>

#include <algorithm>
#include <limits>
#include <tuple>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <new>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "hbvh/builders/build.hpp"
#include "hbvh/fit/volume_policy.hpp"
#include "hbvh/scene/generate.hpp"
#include "hbvh/tree/stats.hpp"
#include "tree/collapse.hpp"

namespace hbvh::bench {
void fail(benchmark::State& state, const std::string& message);
}  // namespace hbvh::bench

namespace hbvh {
namespace {

/// A node of the recorded tree, allocated by Embree's thread-local allocator. Inner nodes and leaves
/// share the layout so that a child pointer says which it is.
struct RecordedNode {
    bool is_leaf = false;
    std::uint32_t child_count = 0;
    RecordedNode* children[2] = {nullptr, nullptr};
    std::uint32_t primitive = 0;      ///< leaves: the one primitive (minLeafSize = maxLeafSize = 1)
    std::uint32_t extra_primitives = 0;  ///< leaves that Embree filled with more than one (expected none)
};

void* create_node(RTCThreadLocalAllocator allocator, unsigned int child_count, void* /*user*/) {
    void* memory = rtcThreadLocalAlloc(allocator, sizeof(RecordedNode), alignof(RecordedNode));
    auto* node = new (memory) RecordedNode;
    node->child_count = child_count;
    return node;
}

void set_children(void* node_pointer, void** children, unsigned int child_count, void* /*user*/) {
    auto* node = static_cast<RecordedNode*>(node_pointer);
    node->child_count = child_count;
    for (unsigned int i = 0; i < child_count && i < 2; ++i) node->children[i] = static_cast<RecordedNode*>(children[i]);
}

void set_bounds(void* /*node*/, const RTCBounds** /*bounds*/, unsigned int /*child_count*/, void* /*user*/) {
    // The cost is recomputed in double from the primitives, so Embree's float bounds are not kept.
}

void* create_leaf(RTCThreadLocalAllocator allocator, const RTCBuildPrimitive* primitives, size_t count, void* /*user*/) {
    void* memory = rtcThreadLocalAlloc(allocator, sizeof(RecordedNode), alignof(RecordedNode));
    auto* leaf = new (memory) RecordedNode;
    leaf->is_leaf = true;
    leaf->primitive = primitives[0].primID;
    leaf->extra_primitives = static_cast<std::uint32_t>(count - 1);
    return leaf;
}

/// Embree's input: each primitive's world AABB rounded outwards to float.
std::vector<RTCBuildPrimitive> embree_primitives(std::span<const Primitive> primitives) {
    std::vector<RTCBuildPrimitive> out(primitives.size());
    const auto down = [](double x) {
        const float f = static_cast<float>(x);
        return static_cast<double>(f) > x ? std::nextafter(f, -INFINITY) : f;
    };
    const auto up = [](double x) {
        const float f = static_cast<float>(x);
        return static_cast<double>(f) < x ? std::nextafter(f, INFINITY) : f;
    };
    for (std::size_t i = 0; i < primitives.size(); ++i) {
        const Aabb box = world_aabb(primitives[i].volume);
        out[i] = {down(box.min.x()), down(box.min.y()), down(box.min.z()), 0u,
                  up(box.max.x()),   up(box.max.y()),   up(box.max.z()),   static_cast<unsigned>(i)};
    }
    return out;
}

/// What a walk of the recorded tree finds.
struct TreeMeasure {
    double cost = 0.0;           ///< AABB Eq. 2
    std::size_t leaves = 0;
    std::size_t extra_primitives = 0;
    std::vector<std::uint32_t> seen;  ///< how often each primitive is in a leaf
};

/// The node's AABB (union of its primitives' world boxes), adding its Eq. 2 term when it is inner.
Aabb measure(const RecordedNode* node, std::span<const Aabb> boxes, TreeMeasure& out) {
    if (node->is_leaf) {
        ++out.leaves;
        out.extra_primitives += node->extra_primitives;
        if (node->primitive < out.seen.size()) ++out.seen[node->primitive];
        return boxes[node->primitive];
    }
    Aabb box = Aabb::empty();
    for (std::uint32_t i = 0; i < node->child_count && i < 2; ++i) box = box.merged(measure(node->children[i], boxes, out));
    out.cost += static_cast<double>(node->child_count) * box.volume();
    return box;
}

/// The recorded tree as a Bvh (breadth-first, as every Bvh is), each inner node the union of its children's
/// boxes, so that hbvh's exact collapse can run on it.
Bvh recorded_bvh(const RecordedNode* root, std::span<const Primitive> primitives, std::span<const Aabb> boxes) {
    Bvh bvh;
    bvh.primitives.assign(primitives.begin(), primitives.end());
    std::vector<const RecordedNode*> order{root};
    bvh.nodes.emplace_back();
    for (std::size_t i = 0; i < order.size(); ++i) {
        const RecordedNode* node = order[i];
        if (node->is_leaf) {
            bvh.nodes[i] = Node{boxes[node->primitive], 0, 0, node->primitive};
            continue;
        }
        bvh.nodes[i].first_child = static_cast<std::uint32_t>(order.size());
        bvh.nodes[i].child_count = node->child_count;
        for (std::uint32_t c = 0; c < node->child_count && c < 2; ++c) {
            order.push_back(node->children[c]);
            bvh.nodes.emplace_back();
        }
    }
    for (std::size_t i = bvh.nodes.size(); i-- > 0;) {
        Node& node = bvh.nodes[i];
        if (node.child_count == 0) continue;
        Aabb box = Aabb::empty();
        for (const Node& child : bvh.children(node)) box = box.merged(std::get<Aabb>(child.volume));
        node.volume = box;
    }
    return bvh;
}

/// Collapsing Embree's tree takes a table of nodes x depth: done up to this size.
constexpr std::uint32_t collapse_embree_max_primitives = 100'000;

struct Row {
    std::string builder;
    double seconds = 0.0;
    double cost = 0.0;
};

/// `with_split_and_scale`: false leaves out the two slow builders (minutes at 10^6), for `binned` against Embree.
void embree_anchor(benchmark::State& state, std::uint32_t count, bool with_split_and_scale) {
    SceneOptions options;
    options.count = count;
    options.seed = 1;
    const std::vector<Primitive> primitives = generate_scene(options);
    std::vector<Aabb> boxes;
    boxes.reserve(primitives.size());
    for (const Primitive& p : primitives) boxes.push_back(world_aabb(p.volume));
    const std::vector<RTCBuildPrimitive> input = embree_primitives(primitives);

    RTCDevice device = rtcNewDevice("threads=2");
    if (device == nullptr) {
        bench::fail(state, "rtcNewDevice failed");
        return;
    }
    std::vector<Row> rows;
    // Embree: the fastest of a few builds (it takes milliseconds at 20 000), each on a fresh copy of the
    // primitive array, which the builder uses as scratch space.
    const int repeats = count <= 100'000 ? 5 : 3;
    Row embree{"embree rtcBuildBVH", 0.0, 0.0};
    const VolumePolicy aabb_only = parse_allowed_types("aabb").value();
    double embree_collapsed_cost = 0.0;
    for (auto _ : state) {
        for (int r = 0; r < repeats; ++r) {
            std::vector<RTCBuildPrimitive> scratch = input;
            RTCBVH bvh = rtcNewBVH(device);
            RTCBuildArguments arguments = rtcDefaultBuildArguments();
            arguments.buildQuality = RTC_BUILD_QUALITY_MEDIUM;  // binned SAH, no spatial splits
            arguments.maxBranchingFactor = 2;
            arguments.maxDepth = 1024;
            arguments.minLeafSize = 1;
            arguments.maxLeafSize = 1;
            arguments.bvh = bvh;
            arguments.primitives = scratch.data();
            arguments.primitiveCount = scratch.size();
            arguments.primitiveArrayCapacity = scratch.size();
            arguments.createNode = create_node;
            arguments.setNodeChildren = set_children;
            arguments.setNodeBounds = set_bounds;
            arguments.createLeaf = create_leaf;
            const auto start = std::chrono::steady_clock::now();
            const auto* root = static_cast<const RecordedNode*>(rtcBuildBVH(&arguments));
            const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            if (root == nullptr) {
                bench::fail(state, "rtcBuildBVH failed: error " + std::to_string(rtcGetDeviceError(device)));
                rtcReleaseBVH(bvh);
                rtcReleaseDevice(device);
                return;
            }
            TreeMeasure tree;
            tree.seen.assign(primitives.size(), 0);
            measure(root, boxes, tree);
            // Embree's binary tree with hbvh's exact collapse applied (wide nodes where they lower Eq. 2), untimed:
            // how much of binned's lead is the collapse, and how much the cuts (docs/scale.md §9).
            if (r == repeats - 1 && count <= collapse_embree_max_primitives && tree.extra_primitives == 0)
                embree_collapsed_cost = cost(detail::collapse_optimally(recorded_bvh(root, primitives, boxes), aabb_only), aabb_only);
            rtcReleaseBVH(bvh);
            // A tree that lost or repeated a primitive would make its cost meaningless.
            if (tree.extra_primitives != 0 || tree.leaves != primitives.size() ||
                std::any_of(tree.seen.begin(), tree.seen.end(), [](std::uint32_t n) { return n != 1; })) {
                bench::fail(state, "Embree's tree does not hold each primitive in its own leaf");
                rtcReleaseDevice(device);
                return;
            }
            embree.seconds = r == 0 ? seconds : std::min(embree.seconds, seconds);
            embree.cost = tree.cost;
        }
    }
    rtcReleaseDevice(device);
    rows.push_back(embree);
    if (embree_collapsed_cost > 0.0) rows.push_back({"embree rtcBuildBVH, collapsed by hbvh (untimed)", 0.0, embree_collapsed_cost});

    // hbvh, every inner node an AABB (`--types aabb`), once each: the builders take seconds to minutes here.
    BuildContext context;
    context.policy = parse_allowed_types("aabb").value();
    // binned, the large-scene builder, takes a fraction of a second: the fastest of three builds, as for Embree.
    for (const auto& [name, algorithm, builds] : {std::tuple{"hbvh split --types aabb", Algorithm::split, 1},
                                                   std::tuple{"hbvh scale --types aabb", Algorithm::scale, 1},
                                                   std::tuple{"hbvh binned --types aabb", Algorithm::binned, 3}}) {
        if (!with_split_and_scale && algorithm != Algorithm::binned) continue;
        Row row{name, std::numeric_limits<double>::infinity(), 0.0};
        for (int b = 0; b < builds; ++b) {
            const auto start = std::chrono::steady_clock::now();
            const Result<Bvh> built = build(primitives, algorithm, context);
            const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            if (!built.has_value()) {
                bench::fail(state, std::string(name) + ": " + built.error().to_string());
                return;
            }
            row.seconds = std::min(row.seconds, seconds);
            row.cost = cost(built.value());
        }
        rows.push_back(row);
    }

    std::printf("\n%u primitives (hbvh generate --count %u --seed 1), AABB Eq. 2 cost\n", count, count);
    std::printf("| builder | build time (s) | cost | time / Embree | cost / Embree |\n|---|---|---|---|---|\n");
    for (const Row& row : rows) {
        if (row.seconds == 0.0)  // untimed
            std::printf("| %s | - | %.4g | - | %.3f |\n", row.builder.c_str(), row.cost, row.cost / embree.cost);
        else
            std::printf("| %s | %.4g | %.4g | %.1f | %.3f |\n", row.builder.c_str(), row.seconds, row.cost,
                        row.seconds / embree.seconds, row.cost / embree.cost);
    }
    std::fflush(stdout);
    state.counters["primitives"] = count;
    state.counters["embree_seconds"] = embree.seconds;
    state.counters["embree_cost"] = embree.cost;
    if (embree_collapsed_cost > 0.0) state.counters["embree_collapsed_cost_ratio"] = embree_collapsed_cost / embree.cost;
    for (const Row& row : rows) {
        if (row.builder.rfind("hbvh ", 0) != 0) continue;  // Embree's own rows
        const std::string builder = row.builder.substr(5, row.builder.find(' ', 5) - 5);  // "hbvh NAME --types aabb"
        state.counters[builder + "_seconds"] = row.seconds;
        state.counters[builder + "_cost_ratio"] = row.cost / embree.cost;
    }

    // All four kinds (hbvh's default): binned against split, whose tree it must not cost more than. At 10^6
    // split needs minutes with every kind's fits, so only binned's time is taken there.
    std::printf("\n%u primitives, all four kinds, Eq. 2 cost\n| builder | build time (s) | cost |\n|---|---|---|\n", count);
    for (const Algorithm algorithm : {Algorithm::binned, Algorithm::split}) {
        if (algorithm == Algorithm::split && (count > 100'000 || !with_split_and_scale)) continue;
        const auto start = std::chrono::steady_clock::now();
        const Result<Bvh> built = build(primitives, algorithm);
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (!built.has_value()) return bench::fail(state, built.error().to_string());
        std::printf("| hbvh %s | %.4g | %.6g |\n", std::string(to_string(algorithm)).c_str(), seconds, cost(built.value()));
    }
    std::fflush(stdout);
}

BENCHMARK_CAPTURE(embree_anchor, 20k, 20'000u, true)->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK_CAPTURE(embree_anchor, 1M, 1'000'000u, true)->Unit(benchmark::kSecond)->Iterations(1);
// binned alone against Embree at 10^6 (seconds, not minutes).
BENCHMARK_CAPTURE(embree_anchor, 1M_binned, 1'000'000u, false)->Unit(benchmark::kSecond)->Iterations(1);

}  // namespace
}  // namespace hbvh
