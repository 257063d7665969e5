// SPDX-License-Identifier: MIT
#include "hbvh/tree/validate.hpp"

#include <algorithm>
#include <cstdio>
#include <optional>
#include <span>
#include <string>
#include <type_traits>
#include <variant>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include "../memory/huge_pages.hpp"
#include "containment.hpp"
#include "hbvh/geometry/validation.hpp"

namespace hbvh {
namespace {
/// Trees from this many nodes on have their primitives and nodes checked by two tasks (below, a second task
/// costs more than it saves).
constexpr std::size_t concurrent_check_nodes = std::size_t{1} << 14;

Error node_error(std::uint32_t index, const std::string& problem) {
    return Error{"node " + std::to_string(index) + ": " + problem};
}

/// Whether two volumes are the same kind with the same numbers (a leaf's copy of its primitive).
bool same_volume(const BoundingVolume& a, const BoundingVolume& b) {
    if (a.index() != b.index()) return false;
    return std::visit(
        [&](const auto& x) {
            using Kind = std::decay_t<decltype(x)>;
            const Kind& y = std::get<Kind>(b);
            if constexpr (std::is_same_v<Kind, Aabb>) return x.min == y.min && x.max == y.max;
            else if constexpr (std::is_same_v<Kind, Obb>)
                return x.center == y.center && x.rotation == y.rotation && x.half_extents == y.half_extents;
            else if constexpr (std::is_same_v<Kind, Sphere>) return x.center == y.center && x.radius == y.radius;
            else return x.p0 == y.p0 && x.p1 == y.p1 && x.radius == y.radius;
        },
        a);
}
}  // namespace

Status check_structure(const Bvh& bvh) {
    if (bvh.nodes.empty()) return bvh.primitives.empty() ? Status{Ok{}} : Status{Error{"hierarchy has no nodes"}};
    if (bvh.nodes.size() >= UINT32_MAX) return Error{"hierarchy has more nodes than 32-bit indices can address"};
    const auto node_count = static_cast<std::uint64_t>(bvh.nodes.size());
    std::vector<std::uint32_t> leaf_of;
    auto check_nodes = [&]() -> Status {
        detail::reserve_on_huge_pages(leaf_of, bvh.primitives.size());
        leaf_of.resize(bvh.primitives.size(), UINT32_MAX);  // UINT32_MAX = not seen yet
        // Breadth-first: the inner nodes' child ranges, in index order, follow each other from node 1 on.
        std::uint64_t next_child = 1;
        for (std::uint32_t i = 0; i < node_count; ++i) {
            const Node& node = bvh.nodes[i];
            if (std::string problem = volume_problem(node.volume); !problem.empty()) return node_error(i, problem);
            if (node.is_leaf()) {
                if (node.primitive >= bvh.primitives.size()) return node_error(i, "leaf refers to a missing primitive");
                if (leaf_of[node.primitive] != UINT32_MAX)
                    return node_error(i, "primitive " + std::to_string(node.primitive) + " appears in two leaves");
                leaf_of[node.primitive] = i;
                // Queries test the leaf's volume and report its primitive: the two must be one shape (only the
                // .hbvh format stores both, and a file could make them differ).
                if (!same_volume(node.volume, bvh.primitives[node.primitive].volume))
                    return node_error(i, "leaf volume differs from its primitive " + std::to_string(node.primitive) + "'s");
                continue;
            }
            if (node.child_count < 2) return node_error(i, "inner node with a single child");
            if (std::uint64_t{node.first_child} + node.child_count > node_count)
                return node_error(i, "child range past the end of the node array");
            // This also rules out cycles and shared children: every child comes after its parent, once.
            if (node.first_child != next_child)
                return node_error(i, "children at " + std::to_string(node.first_child) +
                                         ", but breadth-first order puts them at " + std::to_string(next_child));
            next_child += node.child_count;
        }
        if (next_child != node_count)
            return node_error(static_cast<std::uint32_t>(next_child), "is no node's child (nodes are not one breadth-first tree)");
        return Ok{};
    };
    // The primitives and the nodes are independent checks: a large tree (a loaded 10^6-primitive file) has
    // them made at once, and the primitives' problem is still the one reported when both have one.
    Status primitives = Ok{};
    Status nodes = Ok{};
    if (bvh.nodes.size() >= concurrent_check_nodes)
        tbb::parallel_invoke([&] { primitives = validate_primitives(bvh.primitives); }, [&] { nodes = check_nodes(); });
    else if (primitives = validate_primitives(bvh.primitives); primitives)
        nodes = check_nodes();
    if (!primitives) return primitives;
    if (!nodes) return nodes;
    for (std::uint32_t p = 0; p < bvh.primitives.size(); ++p)
        if (leaf_of[p] == UINT32_MAX) return Error{"primitive " + std::to_string(p) + " is in no leaf"};
    return Ok{};
}

double containment_tolerance(const BoundingVolume& volume, double relative_tolerance) {
    const Aabb box = world_aabb(volume);
    const double magnitude = std::max(box.min.cwiseAbs().maxCoeff(), box.max.cwiseAbs().maxCoeff());
    return relative_tolerance * size_scale(volume) + 1e-14 * magnitude;
}

namespace {
/// The generating spheres of every primitive, leaves in depth-first order, so that the spheres below any node are
/// one run of `spheres` (first_sphere[node] to first_sphere[node] + sphere_count[node]). Before, each node walked
/// its subtree and regenerated each primitive's spheres, through the variant for every sphere.
struct SpheresBelow {
    std::vector<Sphere> spheres;
    std::vector<std::uint32_t> primitive_of;  ///< Per sphere: its primitive (input order).
    std::vector<std::uint64_t> first_sphere;  ///< Per node.
    std::vector<std::uint64_t> sphere_count;  ///< Per node.
};

SpheresBelow spheres_below(const Bvh& bvh) {
    const std::size_t n = bvh.nodes.size();
    SpheresBelow out;
    // Leaves below each node, children (larger indices in breadth-first order) before their parent.
    std::vector<std::uint32_t> leaf_count(n, 0);
    for (std::size_t i = n; i-- > 0;) {
        const Node& node = bvh.nodes[i];
        if (node.is_leaf()) leaf_count[i] = 1;
        for (std::uint32_t c = 0; c < node.child_count; ++c) leaf_count[i] += leaf_count[node.first_child + c];
    }
    // Each node's first leaf in depth-first order, parents before their children.
    std::vector<std::uint32_t> first_leaf(n, 0);
    std::vector<std::uint32_t> leaf_order(bvh.primitives.size(), 0);
    for (std::size_t i = 0; i < n; ++i) {
        const Node& node = bvh.nodes[i];
        if (node.is_leaf()) leaf_order[first_leaf[i]] = node.primitive;
        std::uint32_t next = first_leaf[i];
        for (std::uint32_t c = 0; c < node.child_count; ++c) {
            first_leaf[node.first_child + c] = next;
            next += leaf_count[node.first_child + c];
        }
    }
    std::vector<std::uint64_t> sphere_at_leaf(leaf_order.size() + 1, 0);
    for (std::size_t k = 0; k < leaf_order.size(); ++k) {
        sphere_at_leaf[k] = out.spheres.size();
        append_generating_spheres(bvh.primitives[leaf_order[k]].volume, out.spheres);
        out.primitive_of.resize(out.spheres.size(), leaf_order[k]);
    }
    sphere_at_leaf[leaf_order.size()] = out.spheres.size();
    out.first_sphere.resize(n);
    out.sphere_count.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        out.first_sphere[i] = sphere_at_leaf[first_leaf[i]];
        out.sphere_count[i] = sphere_at_leaf[first_leaf[i] + leaf_count[i]] - out.first_sphere[i];
    }
    return out;
}

/// The sphere of `spheres` that reaches furthest beyond `volume`, past `tolerance` (ties: the lowest primitive);
/// the kind is dispatched once, not per sphere.
std::optional<ContainmentViolation> worst_reach(std::uint32_t node, const BoundingVolume& volume, double tolerance,
                                                std::span<const Sphere> spheres, std::span<const std::uint32_t> primitive_of) {
    double worst = tolerance;
    std::optional<std::uint32_t> primitive;
    std::visit(
        [&](const auto& v) {
            for (std::size_t k = 0; k < spheres.size(); ++k)
                if (const double reach = protrusion(v, spheres[k]);
                    reach > worst || (primitive && reach == worst && primitive_of[k] < *primitive))
                    worst = reach, primitive = primitive_of[k];
        },
        volume);
    if (!primitive) return std::nullopt;
    return ContainmentViolation{node, *primitive, worst};
}
}  // namespace

std::vector<ContainmentViolation> containment_violations(const Bvh& bvh, double relative_tolerance) {
    // Every node against every sphere below it: O(n x height), n log n for a balanced tree and quadratic for a chain,
    // so the runs are contiguous and the nodes checked on every core (a 40 000-deep chain took 8.6 s node by node).
    const SpheresBelow below = spheres_below(bvh);
    std::vector<std::optional<ContainmentViolation>> found(bvh.nodes.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, bvh.nodes.size(), 64), [&](const tbb::blocked_range<std::size_t>& range) {
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
            const BoundingVolume& volume = bvh.nodes[i].volume;
            const auto run = static_cast<std::size_t>(below.first_sphere[i]);
            const auto count = static_cast<std::size_t>(below.sphere_count[i]);
            found[i] = worst_reach(static_cast<std::uint32_t>(i), volume, containment_tolerance(volume, relative_tolerance),
                                   std::span(below.spheres).subspan(run, count),
                                   std::span(below.primitive_of).subspan(run, count));
        }
    });
    std::vector<ContainmentViolation> violations;
    for (const std::optional<ContainmentViolation>& violation : found)
        if (violation) violations.push_back(*violation);
    return violations;
}

std::string describe_violation(const Bvh& bvh, const ContainmentViolation& violation) {
    const std::string& name = bvh.primitives[violation.primitive].name;
    char by[32];
    std::snprintf(by, sizeof by, "%.3g", violation.protrusion);
    return "volume (" + std::string(to_string(type_of(bvh.nodes[violation.node].volume))) +
           ") does not enclose primitive " + std::to_string(violation.primitive) +
           (name.empty() ? std::string{} : " ('" + name + "')") + " by " + by;
}

Status validate(const Bvh& bvh, double relative_tolerance) {
    if (Status structure = check_structure(bvh); !structure) return structure;
    const std::vector<ContainmentViolation> violations = containment_violations(bvh, relative_tolerance);
    if (violations.empty()) return Ok{};
    const ContainmentViolation& first = violations.front();
    return detail::containment_error(first.node, type_of(bvh.nodes[first.node].volume), first.primitive, first.protrusion);
}

Error detail::containment_error(std::uint32_t node, BvType kind, std::uint32_t primitive, double protrusion) {
    char by[32];
    std::snprintf(by, sizeof by, "%.3g", protrusion);
    return node_error(node, "its " + std::string(to_string(kind)) + " does not contain primitive " +
                                std::to_string(primitive) + " (by " + by + ")");
}

}  // namespace hbvh
