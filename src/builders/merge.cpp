// SPDX-License-Identifier: MIT
// OpenTissue's bottom-up construction (Erleben et al., "Physics-Based Animation", 2005; survey §2.3).
#include "hbvh/builders/merge.hpp"

#include <algorithm>
#include <iterator>
#include <limits>
#include <numeric>
#include <optional>
#include <queue>

#include "guarded_build.hpp"
#include "heuristic_support.hpp"
#include "hbvh/assert.hpp"
#include "hbvh/geometry/overlap.hpp"

namespace hbvh {
namespace {

using detail::PrimitiveSet;

// Nodes still without an edge after this many enlargement rounds (a factor of 1.25^40 ~ 7500 at the
// default) are degenerate, e.g. points: they are joined to the nearest graph-node by centre distance.
constexpr int max_enlargement_rounds = 40;

struct GraphNode {
    std::vector<std::uint32_t> covered;     ///< Local primitive indices, ascending.
    std::vector<std::uint32_t> members;     ///< Assembler ids that become the children of the next group.
    std::vector<std::uint32_t> neighbours;  ///< Graph-node ids, ascending.
    std::optional<BoundingVolume> volume;  ///< fit_best over `covered`; made when first needed.
    double priced_volume = 0.0;            ///< The node's volume as Eq. 3 sees it (same fitter as the edges).
    bool alive = true;
};

struct Edge {
    double priority;
    std::uint32_t a, b;  ///< a < b.
    double merged_volume;  ///< Priced volume around both nodes' covered primitives.
};

// Min-heap order. Ties go to the lower node ids; ids are handed out in an order fixed by geometry
// (canonical primitives first, then collapses in order), so no tie depends on input order.
struct LaterEdge {
    bool operator()(const Edge& x, const Edge& y) const {
        if (x.priority != y.priority) return x.priority > y.priority;
        return x.a != y.a ? x.a > y.a : x.b > y.b;
    }
};

class MergeBuilder {
public:
    MergeBuilder(const PrimitiveSet& set, TreeAssembler& assembler, const MergeOptions& options,
                 const detail::Checkpoint& checkpoint)
        : set_(set), assembler_(assembler), checkpoint_(checkpoint), branching_(std::max<std::uint32_t>(options.branching_factor, 2)),
          enlargement_(options.enlargement > 1.0 ? options.enlargement : 1.25), exact_(options.exact_priorities) {}

    std::uint32_t build() {
        for (std::uint32_t local = 0; local < set_.size(); ++local) {
            if (local % 64 == 0) checkpoint_.step(0.0);  // alive_count_ is set after this loop
            GraphNode node;
            node.covered = {local};
            node.members = {assembler_.add_leaf(set_.input_index(local))};
            node.volume = set_.volume_of(local);
            node.priced_volume = price(node.covered);
            nodes_.push_back(std::move(node));
        }
        alive_count_ = set_.size();
        // Stage 1: collapse edges until one graph-node is left, reconnecting whenever edges run out.
        while (alive_count_ > 1) {
            checkpoint();
            if (edge_count_ == 0) connect();
            const Edge edge = pop_live_edge();
            collapse(edge);
        }
        // Stage 2: the last graph-node's pending members become the root group.
        std::uint32_t last = 0;
        while (!nodes_[last].alive) ++last;
        GraphNode& root = nodes_[last];
        if (root.members.size() == 1) return root.members.front();
        return assembler_.add_group(root.members, volume_of(root));
    }

private:
    /// The deadline and progress, between collapses and inside the loops that build the graph: at 20 000
    /// primitives pricing the first edges alone took seconds, and a 0.5 s limit was kept only after 4-5 s.
    void checkpoint() const { checkpoint_.step(static_cast<double>(set_.size() - alive_count_)); }

    // Builds edges among all live graph-nodes by the enlarged-BV overlap rule (survey §2.3), enlarging
    // isolated nodes again until each has an edge: the survey's fix for the fixed 25 % leaving nodes alone.
    void connect() {
        std::vector<std::uint32_t> live;
        for (std::uint32_t id = 0; id < nodes_.size(); ++id)
            if (nodes_[id].alive) live.push_back(id);
        const std::size_t count = live.size();
        std::vector<double> factor(count, enlargement_);
        std::vector<BoundingVolume> grown(count);
        std::vector<Aabb> boxes(count);
        std::vector<bool> connected(count, false);
        const auto grow = [&](std::size_t i) {
            grown[i] = detail::enlarged(volume_of(nodes_[live[i]]), factor[i]);
            boxes[i] = world_aabb(grown[i]);
        };
        const auto try_pair = [&](std::size_t i, std::size_t j) {
            const Aabb& p = boxes[i];
            const Aabb& q = boxes[j];
            if ((p.min.array() > q.max.array()).any() || (q.min.array() > p.max.array()).any()) return;
            if (!overlaps(grown[i], grown[j])) return;
            add_edge(live[i], live[j]);
            connected[i] = connected[j] = true;
        };
        for (std::size_t i = 0; i < count; ++i) grow(i);

        // Sweep and prune on x, then the exact test: near n log n for artists' scenes.
        std::vector<std::size_t> by_x(count);
        std::iota(by_x.begin(), by_x.end(), std::size_t{0});
        std::sort(by_x.begin(), by_x.end(), [&](std::size_t a, std::size_t b) {
            return boxes[a].min.x() != boxes[b].min.x() ? boxes[a].min.x() < boxes[b].min.x() : a < b;
        });
        for (std::size_t s = 0; s < count; ++s) {
            checkpoint();
            for (std::size_t t = s + 1; t < count && boxes[by_x[t]].min.x() <= boxes[by_x[s]].max.x(); ++t)
                try_pair(by_x[s], by_x[t]);
        }

        for (int round = 0; round < max_enlargement_rounds; ++round) {
            std::vector<std::size_t> isolated;
            for (std::size_t i = 0; i < count; ++i)
                if (!connected[i]) isolated.push_back(i);
            if (isolated.empty()) break;
            for (const std::size_t i : isolated) {
                factor[i] *= enlargement_;
                grow(i);
            }
            for (const std::size_t i : isolated) {
                checkpoint();
                for (std::size_t j = 0; j < count; ++j)
                    if (j != i && !has_edge(live[i], live[j])) try_pair(i, j);
            }
        }
        for (std::size_t i = 0; i < count; ++i)
            if (!connected[i]) connect_nearest(live, i, connected);
    }

    // Degenerate fallback: the live graph-node with the nearest BV centre, ties to the lower id.
    void connect_nearest(const std::vector<std::uint32_t>& live, std::size_t i, std::vector<bool>& connected) {
        const Vec3 centre = world_aabb(volume_of(nodes_[live[i]])).center();
        double best = std::numeric_limits<double>::infinity();
        std::size_t nearest = i;
        for (std::size_t j = 0; j < live.size(); ++j) {
            if (j == i) continue;
            const double d = (world_aabb(volume_of(nodes_[live[j]])).center() - centre).squaredNorm();
            if (d < best) {
                best = d;
                nearest = j;
            }
        }
        if (nearest == i || has_edge(live[i], live[nearest])) return;
        add_edge(live[i], live[nearest]);
        connected[i] = connected[nearest] = true;
    }

    bool has_edge(std::uint32_t a, std::uint32_t b) const {
        const auto& n = nodes_[a].neighbours;
        return std::binary_search(n.begin(), n.end(), b);
    }

    void insert_neighbour(std::uint32_t node, std::uint32_t neighbour) {
        auto& n = nodes_[node].neighbours;
        n.insert(std::lower_bound(n.begin(), n.end(), neighbour), neighbour);
    }

    void add_edge(std::uint32_t a, std::uint32_t b) {
        if (a > b) std::swap(a, b);
        insert_neighbour(a, b);
        insert_neighbour(b, a);
        ++edge_count_;
        push_edge(a, b);
    }

    // Eq. 3: weighted volume of the BV around both nodes' primitives minus the nodes' own volumes.
    void push_edge(std::uint32_t a, std::uint32_t b) {
        if (a > b) std::swap(a, b);
        std::vector<std::uint32_t> both;
        std::merge(nodes_[a].covered.begin(), nodes_[a].covered.end(), nodes_[b].covered.begin(),
                   nodes_[b].covered.end(), std::back_inserter(both));
        const double merged = price(both);
        heap_.push(Edge{merged - nodes_[a].priced_volume - nodes_[b].priced_volume, a, b, merged});
    }

    double price(std::span<const std::uint32_t> covered) const {
        return exact_ ? set_.weighted_volume(set_.fit(covered)) : set_.estimate(covered);
    }

    const BoundingVolume& volume_of(GraphNode& node) const {
        if (!node.volume) node.volume = set_.fit(node.covered);
        return *node.volume;
    }

    // Lazy invalidation: an edge is stale once either end has been collapsed into a new graph-node.
    Edge pop_live_edge() {
        while (true) {
            HBVH_ASSERT(!heap_.empty());  // edge_count_ > 0 means a live edge is queued
            Edge edge = heap_.top();
            heap_.pop();
            if (nodes_[edge.a].alive && nodes_[edge.b].alive) return edge;
        }
    }

    void collapse(const Edge& edge) {
        GraphNode& a = nodes_[edge.a];
        GraphNode& b = nodes_[edge.b];
        GraphNode merged;
        std::merge(a.covered.begin(), a.covered.end(), b.covered.begin(), b.covered.end(),
                   std::back_inserter(merged.covered));
        merged.members = a.members;
        merged.members.insert(merged.members.end(), b.members.begin(), b.members.end());
        std::set_union(a.neighbours.begin(), a.neighbours.end(), b.neighbours.begin(), b.neighbours.end(),
                       std::back_inserter(merged.neighbours));
        std::erase_if(merged.neighbours, [&](std::uint32_t id) { return id == edge.a || id == edge.b; });
        merged.priced_volume = edge.merged_volume;
        edge_count_ = edge_count_ + 1 - a.neighbours.size() - b.neighbours.size() + merged.neighbours.size();

        const auto id = static_cast<std::uint32_t>(nodes_.size());
        for (const std::uint32_t x : merged.neighbours) {
            auto& n = nodes_[x].neighbours;
            std::erase_if(n, [&](std::uint32_t y) { return y == edge.a || y == edge.b; });
            n.push_back(id);  // id is the largest so far: the list stays sorted
        }
        for (GraphNode* dead : {&a, &b}) {
            dead->alive = false;
            dead->covered = {};
            dead->members = {};
            dead->neighbours = {};
        }
        --alive_count_;

        // Merge postponement (survey §2.3, OpenTissue's default policy): make a BVH group only when the
        // graph-node already covers enough BVH nodes or the graph is nearly used up; otherwise the
        // graph-node just carries the union and is grouped in a later collapse.
        if (merged.members.size() >= branching_ || edge_count_ < branching_)
            merged.members = {assembler_.add_group(merged.members, volume_of(merged))};
        const std::vector<std::uint32_t> neighbours = merged.neighbours;
        nodes_.push_back(std::move(merged));
        for (const std::uint32_t x : neighbours) push_edge(x, id);
    }

    const PrimitiveSet& set_;
    TreeAssembler& assembler_;
    const detail::Checkpoint& checkpoint_;
    std::uint32_t branching_;
    double enlargement_;
    bool exact_;
    std::vector<GraphNode> nodes_;
    std::priority_queue<Edge, std::vector<Edge>, LaterEdge> heap_;
    std::size_t edge_count_ = 0;
    std::uint32_t alive_count_ = 0;
};

}  // namespace

Result<Bvh> build_merge(std::span<const Primitive> primitives, const BuildContext& context,
                        const MergeOptions& options) {
    return detail::guarded_build(primitives, context, "merge", static_cast<double>(primitives.size()),
                                 [&](const detail::Checkpoint& checkpoint) {
                                     const PrimitiveSet set(primitives, detail::canonical_order(primitives), context.policy);
                                     TreeAssembler assembler(primitives);
                                     const std::uint32_t root = MergeBuilder(set, assembler, options, checkpoint).build();
                                     return std::move(assembler).finish(root);
                                 });
}

}  // namespace hbvh
