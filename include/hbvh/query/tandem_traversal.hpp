// SPDX-License-Identifier: MIT
// Collision queries between two posed hierarchies: tandem traversal and the two-level baseline.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <stdexcept>
#include <string_view>
#include <utility>
#include <vector>

#include "hbvh/result.hpp"
#include "hbvh/tree/bvh.hpp"
#include "hbvh/tree/validate.hpp"

namespace hbvh {

/// What a query reports.
enum class CollideMode : std::uint8_t {
    all,    ///< Every overlapping primitive pair.
    first,  ///< Stop at the first overlapping primitive pair found.
};

/// Outcome of one query, with the work it took.
struct CollideResult {
    bool intersecting = false;
    /// Overlapping pairs (primitive of a, primitive of b), as indices into each Bvh's input order, sorted.
    /// In CollideMode::first it holds the one pair found (or nothing).
    std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
    std::uint64_t bv_tests = 0;         ///< Overlap tests in which at least one volume is an inner node's.
    std::uint64_t primitive_tests = 0;  ///< Overlap tests between two leaves (exact primitive geometry).
    std::uint64_t nodes_visited = 0;    ///< Node pairs that passed the conservative inner test, then were expanded
                                        ///< or reported.
    /// Set when the query was refused (a pose that is no rigid motion, or for the Bvh overloads a hierarchy
    /// that fails check_structure()); the rest of the result is then empty. Poses made by
    /// RigidTransform::from_quaternion from a non-zero quaternion are never refused.
    std::optional<Error> error;
};

/// Thrown by QueryTree's constructor for a Bvh that fails check_structure(); QueryTree::create returns the
/// same Error instead of throwing.
class InvalidHierarchy : public std::invalid_argument {
public:
    explicit InvalidHierarchy(Error error) : std::invalid_argument(error.to_string()), error_(std::move(error)) {}
    [[nodiscard]] const Error& error() const { return error_; }

private:
    Error error_;
};

/// One node of a QueryTree: the hot data of the traversal, 160 bytes. Same indices as the Bvh it came
/// from; everything in the Bvh's model frame. The exact BV lives in QueryTree::volume(i) (cold).
/// Every node carries two conservative stand-ins for its BV, so that inner tests never read the variant:
/// an enclosing sphere and an enclosing box (the BV itself for an Aabb or Obb; for a capsule the box along
/// its segment, for a sphere the cube around it).
struct QueryNode {
    Vec3 center;                    ///< Box / sphere centre, capsule midpoint: the centre of both stand-ins.
    double sphere_radius = 0.0;     ///< Radius of a sphere around the BV, padded by 1e-12 x (radius + |center|_1).
    Mat3 rotation;                  ///< The enclosing box's axes as columns (identity for an Aabb and a sphere).
    Vec3 half_extents;              ///< The enclosing box's half extents.
    double measure = 0.0;           ///< volume(volume): the descent rule compares these.
    std::uint32_t first_child = 0;  ///< Children: [first_child, first_child + child_count).
    std::uint32_t child_count = 0;  ///< 0 for a leaf.
    std::uint32_t primitive = 0;    ///< For a leaf: the primitive's index in input order.
    std::uint32_t leaf_begin = 0;   ///< The subtree's leaves: QueryTree::leaves()[leaf_begin, leaf_begin + leaf_count).
    std::uint32_t leaf_count = 0;   ///< Leaves below (1 for a leaf).
    BvType type = BvType::aabb;     ///< The kind of the node's BV.
    bool axis_aligned = true;       ///< rotation is the identity (an Aabb or a sphere): box tests skip a product.
};

/// The read-only layout queries run on, converted once from a Bvh (which stays the ground truth):
/// flat node array, children contiguous, every node with an enclosing sphere and an enclosing box and its
/// volume precomputed, the exact BVs in a separate array, the leaves in depth-first order, and the stack
/// depth a traversal can need.
class QueryTree {
public:
    /// Converts `bvh` after check_structure(bvh) (linear time): a malformed Bvh (child ranges past the end,
    /// a non-breadth-first order, NaN or negative geometry, a box whose axes are no rotation) throws
    /// InvalidHierarchy instead of being read out of bounds or pruned on. Whether volumes enclose their
    /// primitives is validate()'s job (every node against every primitive below it: O(n log n) for a balanced
    /// tree, quadratic for a chain), run by every CLI command on stored files.
    /// An empty Bvh gives an empty tree, which collides with nothing.
    explicit QueryTree(const Bvh& bvh);
    /// As the constructor, returning the Error instead of throwing.
    [[nodiscard]] static Result<QueryTree> create(const Bvh& bvh);
    /// Reads a .hbvh hierarchy straight into the query layout, with no Bvh in between: for a program that
    /// loads trees at start-up only to query them (at 10^6 primitives about half the memory and half the time
    /// of hbvh::read_binary followed by create; docs/formats.md, "Load time"). Refuses what read_binary
    /// refuses, with the same Error, and a file that holds a primitive set rather than a hierarchy.
    [[nodiscard]] static Result<QueryTree> read_binary(std::span<const std::byte> bytes, std::string_view source_name);
    /// As above, from the file at `path` (mapped when it is large); errors name the file as given.
    [[nodiscard]] static Result<QueryTree> read_binary_file(const std::filesystem::path& path);

    /// True for a tree converted from an empty Bvh.
    [[nodiscard]] bool empty() const { return nodes_.empty(); }
    /// All nodes, root first, breadth-first as in the Bvh (model frame).
    [[nodiscard]] std::span<const QueryNode> nodes() const { return nodes_; }
    /// The exact BV of node i (for a leaf: its primitive's geometry), as in the Bvh.
    [[nodiscard]] const BoundingVolume& volume(std::uint32_t i) const { return volumes_[i]; }
    /// Leaf node index of each primitive, in input order.
    [[nodiscard]] std::span<const std::uint32_t> primitive_nodes() const { return primitive_nodes_; }
    /// Largest sum of child counts along a root-to-leaf path: this tree's share of the traversal stack.
    [[nodiscard]] std::uint32_t stack_bound() const { return stack_bound_; }
    /// Leaf node indices in depth-first order, so that every subtree's leaves are one contiguous range
    /// (QueryNode::leaf_begin, leaf_count): small node pairs are tested leaf by leaf from it.
    [[nodiscard]] std::span<const std::uint32_t> leaves() const { return leaves_; }
    /// Trees of up to this many leaves also keep their leaves in contact_order().
    static constexpr std::size_t contact_order_max_leaves = 4096;
    /// The leaves (node indices) ordered by the cost of their exact test, cheapest first: spheres, capsules,
    /// boxes, oriented boxes (measured: 6, 33, 40 and 48 ns for a moved leaf against its own copy), depth-first
    /// within a kind. Where most leaf pairs meet and any contact answers the query (mode first on nearly
    /// concentric roots), the cheapest pairs are worth trying first (docs/queries.md, "Concentric roots").
    /// Empty for a tree of more than contact_order_max_leaves leaves.
    [[nodiscard]] std::span<const std::uint32_t> contact_order() const { return contact_order_; }
    /// Largest |center|_1 of any node: with extent_bound(), what rounding in a box test is relative to.
    [[nodiscard]] double coordinate_bound() const { return coordinate_bound_; }
    /// Largest sum of a node's enclosing-box half extents.
    [[nodiscard]] double extent_bound() const { return extent_bound_; }

private:
    struct Checked {};  // the Bvh passed check_structure()
    static Checked checked_or_throw(const Bvh& bvh);
    QueryTree(const Bvh& bvh, Checked);
    QueryTree() = default;

    /// Where the breadth-first links of the nodes added so far lead (see add_volume_and_links).
    struct LinkState {
        std::vector<std::uint32_t> path_sum;  ///< Per node: sum of child counts from the root down to it.
        std::uint64_t next_child = 1;         ///< Where the next inner node's children must start.
    };
    /// Room for add_stand_ins' nodes; and for add_volume_and_links' arrays (so two tasks can fill one each).
    void reserve_stand_ins(std::size_t node_count);
    void reserve_volumes_and_links(std::size_t node_count, std::size_t primitive_count, LinkState& links);
    /// Appends node `node`'s QueryNode (its stand-ins, measure, links and kind).
    void add_stand_ins(const Node& node);
    /// Node i's share of primitive_nodes_ and stack_bound_, and its exact volume appended. Every index taken
    /// from the node is checked first, so a loaded file's nodes can be added before their structure is known
    /// to be sound (what breaks it is refused afterwards; the work stays linear whatever the node says).
    void add_volume_and_links(std::uint32_t i, const Node& node, LinkState& links);
    /// The leaves in depth-first order and each node's leaf range: once every node is in and the structure sound.
    void finish();

    std::vector<QueryNode> nodes_;
    std::vector<BoundingVolume> volumes_;
    std::vector<std::uint32_t> primitive_nodes_;
    std::vector<std::uint32_t> leaves_;
    std::vector<std::uint32_t> contact_order_;
    std::uint32_t stack_bound_ = 0;
    double coordinate_bound_ = 0.0;
    double extent_bound_ = 0.0;
};

/// The containment check of a loaded tree, as validate(const Bvh&) makes it after check_structure(): every inner
/// node's volume holds every leaf below it (relative tolerance, see containment_tolerance). For a program that
/// loads with QueryTree::read_binary_file, which, as every reader, checks the structure (and that each leaf is its
/// primitive) but not containment. O(n x depth). The Error names the first node that fails and its primitive
/// that reaches furthest out, in validate()'s words.
[[nodiscard]] Status validate(const QueryTree& tree, double relative_tolerance = default_containment_tolerance);

/// The pose of b's model frame relative to a's: maps b-model coordinates to a-model coordinates.
/// Queries run in a's model frame, so this is the one transform a query computes.
[[nodiscard]] RigidTransform relative_transform(const RigidTransform& pose_a, const RigidTransform& pose_b);

/// Node pairs whose leaf counts multiply to at most this are tested leaf by leaf, as the two-level query
/// does: below it the inner tests a descent would spend cost more than the leaf tests they save
/// (measured in docs/queries.md, "Flat pairs").
inline constexpr std::uint64_t default_flat_pair_limit = 32;

/// Tandem traversal (Erleben et al. 2005): from the root pair, expand the node with the larger volume
/// (or the inner one, if the other is a leaf) and test its children against the other node; leaf pairs
/// are exact primitive tests. Inner pairs are tested conservatively (enclosing spheres, then enclosing
/// boxes by their six face axes), which never drops a pair but may expand a few more; a pair of subtrees
/// with at most `flat_pair_limit` leaf pairs is tested leaf by leaf, and so are two small trees whose roots
/// nearly share a centre (copies on top of each other, where the survey's Two-Level query wins; at most 1024
/// leaf pairs, 4096 in mode first; larger ones get 64 leaf pairs tried before the descent in mode first;
/// docs/queries.md, "Concentric roots"). 0: always descend. pose_a / pose_b
/// map each tree's model frame to the world. Each of b's leaves is moved into a's frame at most once per
/// query, into a per-thread scratch that grows once to min(b's nodes, 4096) slots; nothing else allocates
/// except growing `result.pairs` (and a heap stack when the two trees' stack bounds add up to more than
/// the built-in 1024 entries). `result` is overwritten; reusing it across queries keeps the pairs' capacity.
/// Each pose is checked once per query (validate_pose: finite, a proper rotation within 1e-9); a bad one
/// sets result.error and nothing else.
void collide(const QueryTree& a, const RigidTransform& pose_a, const QueryTree& b, const RigidTransform& pose_b,
             CollideMode mode, CollideResult& result, std::uint64_t flat_pair_limit = default_flat_pair_limit);
/// As above, returning a fresh result.
[[nodiscard]] CollideResult collide(const QueryTree& a, const RigidTransform& pose_a, const QueryTree& b,
                                    const RigidTransform& pose_b, CollideMode mode = CollideMode::all);
/// Convenience for one-off queries: converts both Bvhs first (allocates; keep QueryTrees for many queries).
[[nodiscard]] CollideResult collide(const Bvh& a, const RigidTransform& pose_a, const Bvh& b,
                                    const RigidTransform& pose_b, CollideMode mode = CollideMode::all);

/// The survey's Two-Level baseline: test the roots, and if they overlap test every primitive pair.
/// Same frames, counters and results as collide().
void collide_two_level(const QueryTree& a, const RigidTransform& pose_a, const QueryTree& b,
                       const RigidTransform& pose_b, CollideMode mode, CollideResult& result);
/// As above, returning a fresh result.
[[nodiscard]] CollideResult collide_two_level(const QueryTree& a, const RigidTransform& pose_a, const QueryTree& b,
                                              const RigidTransform& pose_b, CollideMode mode = CollideMode::all);
/// Convenience for one-off queries on Bvhs (allocates).
[[nodiscard]] CollideResult collide_two_level(const Bvh& a, const RigidTransform& pose_a, const Bvh& b,
                                              const RigidTransform& pose_b, CollideMode mode = CollideMode::all);

}  // namespace hbvh
