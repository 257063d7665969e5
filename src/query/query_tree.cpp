// SPDX-License-Identifier: MIT
// QueryTree: the read-only layout queries run on, converted once from a Bvh.
#include <algorithm>
#include <optional>
#include <string>

#include <tbb/parallel_invoke.h>

#include "../fit/frames.hpp"
#include "../memory/huge_pages.hpp"
#include "../tree/binary_decoding.hpp"
#include "../tree/containment.hpp"
#include "hbvh/assert.hpp"
#include "hbvh/query/tandem_traversal.hpp"
#include "hbvh/tree/binary_format.hpp"
#include "hbvh/tree/validate.hpp"

namespace hbvh {
namespace {

// Stand-ins are padded so that rounding can never make a pre-test reject a pair the exact test would
// accept: rounding in the radius (relative to it), and in the centre, which a transform moves with an
// error of a few ulps of its coordinates (a radius-1 sphere at 1e5 lands ~2e-11 off). The pad, 1e-12 of
// radius + |centre|_1, dominates both and the exact tests' own slacks (<= 1e-13 of the coordinates,
// geometry/overlap.cpp).
constexpr double stand_in_padding = 1e-12;

// Trees from this many nodes on are converted by two tasks (below, a second task costs more than it saves).
constexpr std::uint32_t concurrent_conversion_nodes = 1u << 14;

// The traversal reads one node per test: keep it compact (docs/queries.md, "Query layout").
static_assert(sizeof(QueryNode) == 160);

/// The sphere and box stand-ins of `bv` (not the smallest; cheap and tight enough to reject).
void set_stand_ins(const BoundingVolume& bv, QueryNode& q) {
    q.rotation = Mat3::Identity();
    q.axis_aligned = true;
    switch (bv.index()) {
        case 0: {
            const Aabb& box = *std::get_if<Aabb>(&bv);
            q.center = box.center();
            q.half_extents = box.half_extents();
            q.sphere_radius = q.half_extents.norm();
            break;
        }
        case 1: {
            const Obb& box = *std::get_if<Obb>(&bv);
            q.center = box.center;
            q.rotation = box.rotation;
            q.axis_aligned = false;
            q.half_extents = box.half_extents;
            q.sphere_radius = box.half_extents.norm();
            break;
        }
        case 2: {
            const Sphere& s = *std::get_if<Sphere>(&bv);
            q.center = s.center;
            q.half_extents = Vec3::Constant(s.radius);
            q.sphere_radius = s.radius;
            break;
        }
        default: {
            const Capsule& c = *std::get_if<Capsule>(&bv);
            const double half_length = 0.5 * c.length();
            q.center = c.center();
            // The box along the segment: x on the axis, half extents (L/2 + r, r, r).
            if (half_length > 0.0) {
                q.rotation = detail::frame_from_axis(c.p1 - c.p0);
                q.axis_aligned = false;
            }
            q.half_extents = Vec3(half_length + c.radius, c.radius, c.radius);
            q.sphere_radius = half_length + c.radius;
            break;
        }
    }
    const double pad = stand_in_padding * (q.sphere_radius + q.center.cwiseAbs().sum());
    q.sphere_radius += pad;
    q.half_extents.array() += pad;
}

}  // namespace

QueryTree::Checked QueryTree::checked_or_throw(const Bvh& bvh) {
    if (Status structure = check_structure(bvh); !structure) throw InvalidHierarchy(structure.error());
    return Checked{};
}

QueryTree::QueryTree(const Bvh& bvh) : QueryTree(bvh, checked_or_throw(bvh)) {}

Result<QueryTree> QueryTree::create(const Bvh& bvh) {
    if (Status structure = check_structure(bvh); !structure) return structure.error();
    return QueryTree(bvh, Checked{});
}

// Huge pages for the large arrays: a tree loaded at start-up is converted once, and at 10^6 primitives its
// 300 MB in 4 KiB pages cost most of a second in page faults on the machine of docs/formats.md.
void QueryTree::reserve_stand_ins(std::size_t node_count) { detail::reserve_on_huge_pages(nodes_, node_count); }

void QueryTree::reserve_volumes_and_links(std::size_t node_count, std::size_t primitive_count, LinkState& links) {
    detail::reserve_on_huge_pages(volumes_, node_count);
    detail::reserve_on_huge_pages(primitive_nodes_, primitive_count);
    primitive_nodes_.resize(primitive_count, 0);
    detail::reserve_on_huge_pages(links.path_sum, node_count);
    links.path_sum.resize(node_count, 0);
}

void QueryTree::add_stand_ins(const Node& node) {
    QueryNode q;
    set_stand_ins(node.volume, q);
    q.measure = hbvh::volume(node.volume);
    q.first_child = node.first_child;
    q.child_count = node.child_count;
    q.primitive = node.primitive;
    q.type = type_of(node.volume);
    coordinate_bound_ = std::max(coordinate_bound_, q.center.cwiseAbs().sum());
    extent_bound_ = std::max(extent_bound_, q.half_extents.sum());
    nodes_.push_back(q);
}

void QueryTree::add_volume_and_links(std::uint32_t i, const Node& node, LinkState& links) {
    volumes_.push_back(node.volume);
    std::vector<std::uint32_t>& path_sum = links.path_sum;
    if (node.is_leaf()) {
        if (node.primitive < primitive_nodes_.size()) primitive_nodes_[node.primitive] = i;
    } else if (node.first_child == links.next_child && node.first_child > i &&
               std::uint64_t{node.first_child} + node.child_count <= path_sum.size()) {
        // Breadth-first, so a parent's path sum is final before its children are reached.
        for (std::uint32_t c = node.first_child; c < node.first_child + node.child_count; ++c)
            path_sum[c] = path_sum[i] + node.child_count;
        links.next_child += node.child_count;
    } else {
        links.next_child = UINT64_MAX;  // not breadth-first: refused later; no more links are followed
    }
    if (i < path_sum.size()) stack_bound_ = std::max(stack_bound_, path_sum[i]);
}

QueryTree::QueryTree(const Bvh& bvh, Checked) {
    const auto node_count = static_cast<std::uint32_t>(bvh.nodes.size());
    LinkState links;
    // Two independent passes over the Bvh, each writing its own arrays and bounds (so the result does not
    // depend on the thread count): the nodes' stand-ins, and the exact volumes with the links.
    auto convert_nodes = [&] {
        reserve_stand_ins(node_count);
        for (const Node& node : bvh.nodes) add_stand_ins(node);
    };
    auto copy_volumes_and_links = [&] {
        reserve_volumes_and_links(node_count, bvh.primitives.size(), links);
        for (std::uint32_t i = 0; i < node_count; ++i) add_volume_and_links(i, bvh.nodes[i], links);
    };
    if (node_count >= concurrent_conversion_nodes) tbb::parallel_invoke(convert_nodes, copy_volumes_and_links);
    else {
        convert_nodes();
        copy_volumes_and_links();
    }
    finish();
}

Result<QueryTree> QueryTree::read_binary(std::span<const std::byte> bytes, std::string_view source_name) {
    // Each node goes into the query layout as it is decoded, by two passes over the node records that fill
    // different arrays (as the conversion from a Bvh does); the structure's checks run alongside and decide at
    // the end (add_volume_and_links is safe on any node meanwhile).
    class StandIns final : public detail::BinaryNodeSink {
    public:
        explicit StandIns(QueryTree& tree) : tree_(tree) {}
        void reserve(std::uint64_t node_count, std::uint64_t /*primitive_count*/) override { tree_.reserve_stand_ins(node_count); }
        void add(const Node& node) override { tree_.add_stand_ins(node); }

    private:
        QueryTree& tree_;
    };
    class VolumesAndLinks final : public detail::BinaryNodeSink {
    public:
        explicit VolumesAndLinks(QueryTree& tree) : tree_(tree) {}
        void reserve(std::uint64_t node_count, std::uint64_t primitive_count) override {
            tree_.reserve_volumes_and_links(node_count, primitive_count, links_);
        }
        void add(const Node& node) override { tree_.add_volume_and_links(next_++, node, links_); }

    private:
        QueryTree& tree_;
        LinkState links_;
        std::uint32_t next_ = 0;
    };
    const std::string file(source_name);
    QueryTree tree;
    StandIns stand_ins(tree);
    VolumesAndLinks volumes_and_links(tree);
    detail::BinaryNodeSink* const sinks[] = {&stand_ins, &volumes_and_links};
    const Result<detail::DecodedBinary> decoded = detail::decode_binary(bytes, file, sinks, nullptr);
    if (!decoded) return decoded.error();
    if (!decoded->sound) {
        // Something may be wrong: the Bvh reader's full checks decide, and name the problem as it does.
        Result<Bvh> checked = hbvh::read_binary(bytes, source_name);
        if (!checked) return checked.error();
    }
    if (decoded->node_count == 0)
        return Error{"holds a primitive set, not a hierarchy: build one (hbvh build) before querying it", file};
    tree.finish();
    return tree;
}

Status validate(const QueryTree& tree, double relative_tolerance) {
    std::vector<Sphere> spheres;
    for (std::uint32_t i = 0; i < tree.nodes().size(); ++i) {
        const QueryNode& node = tree.nodes()[i];
        if (node.child_count == 0) continue;
        const BoundingVolume& volume = tree.volume(i);
        detail::WorstReach worst(volume, containment_tolerance(volume, relative_tolerance), spheres);
        for (const std::uint32_t leaf : tree.leaves().subspan(node.leaf_begin, node.leaf_count))
            worst.add(tree.nodes()[leaf].primitive, tree.volume(leaf));
        if (worst.primitive()) return detail::containment_error(i, type_of(volume), *worst.primitive(), worst.reach());
    }
    return Ok{};
}

Result<QueryTree> QueryTree::read_binary_file(const std::filesystem::path& path) {
    std::optional<Result<QueryTree>> tree;
    const Status read = detail::with_file_bytes(path, [&](std::span<const std::byte> bytes) { tree = read_binary(bytes, path.string()); });
    if (!read) return read.error();
    return std::move(*tree);
}

void QueryTree::finish() {
    if (nodes_.empty()) return;
    // Leaves in depth-first order (an explicit stack: trees may be as deep as they have primitives), each
    // subtree's range closed once its last leaf is placed: children have larger indices than their parent,
    // so a reverse sweep sums the ranges bottom-up.
    detail::reserve_on_huge_pages(leaves_, primitive_nodes_.size());
    std::vector<std::uint32_t> pending{0};
    while (!pending.empty()) {
        const std::uint32_t i = pending.back();
        pending.pop_back();
        QueryNode& q = nodes_[i];
        if (q.child_count == 0) {
            q.leaf_begin = static_cast<std::uint32_t>(leaves_.size());
            q.leaf_count = 1;
            leaves_.push_back(i);
            continue;
        }
        for (std::uint32_t c = q.first_child + q.child_count; c-- > q.first_child;) pending.push_back(c);
    }
    if (leaves_.size() <= contact_order_max_leaves) {
        // A stable bucket pass by kind, cheapest exact test first.
        contact_order_.reserve(leaves_.size());
        for (const BvType kind : {BvType::sphere, BvType::capsule, BvType::aabb, BvType::obb})
            for (const std::uint32_t leaf : leaves_)
                if (nodes_[leaf].type == kind) contact_order_.push_back(leaf);
    }
    for (std::uint32_t i = static_cast<std::uint32_t>(nodes_.size()); i-- > 0;) {
        QueryNode& q = nodes_[i];
        if (q.child_count == 0) continue;
        const QueryNode& first = nodes_[q.first_child];
        q.leaf_begin = first.leaf_begin;
        q.leaf_count = 0;
        for (std::uint32_t c = q.first_child; c < q.first_child + q.child_count; ++c) q.leaf_count += nodes_[c].leaf_count;
    }
}

}  // namespace hbvh
