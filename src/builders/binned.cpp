// SPDX-License-Identifier: MIT
// binned: top-down binned splits on a volume heuristic, the Eq. 2-optimal collapse into wide nodes, then one
// fit per kept node (docs/scale.md §9).
#include "hbvh/builders/binned.hpp"

#include <Eigen/Eigenvalues>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <optional>
#include <tuple>
#include <vector>

#include "guarded_build.hpp"
#include "heuristic_support.hpp"
#include "../memory/huge_pages.hpp"
#include "hbvh/builders/split.hpp"
#include "hbvh/fit/fit.hpp"
#include "hbvh/tree/stats.hpp"
#include "../fit/frames.hpp"

namespace hbvh {
namespace binned_internal {  // named, so that a unity build's other anonymous helpers cannot collide
namespace {

using detail::LargeVector;
using detail::PrimitiveSet;

constexpr std::uint32_t max_children_limit = 16;
/// A binary node's collapse costs: entry k (1..max_children) is the least Eq. 2 cost its subtree adds when it
/// makes k children of its nearest kept ancestor (collapse_costs).
using CollapseCosts = std::array<double, max_children_limit + 1>;
/// Ranges up to this size are swept with per-side fits (estimate_sweep_cut) in small inputs, as split does.
constexpr std::size_t estimate_sweep_max_primitives = 64;
/// Ranges up to this size may look ahead (BinnedOptions::lookahead_depth): each trial plans the whole range.
constexpr std::size_t lookahead_max_primitives = 64;
constexpr double infinity = std::numeric_limits<double>::infinity();

double box_area(const Aabb& box) {
    const Vec3 e = (box.max - box.min).cwiseMax(0.0);
    return e.x() * e.y() + e.y() * e.z() + e.z() * e.x();
}

/// What a side of a cut of `count` primitives is expected to add to Eq. 2, per unit of its volume. A subtree
/// over m primitives whose volume halves from level to level costs about 2 x volume x log2 m (each of its
/// log2 m levels adds twice the volume it covers), and a single primitive adds nothing of its own. This
/// weighting made trees 2-3 % cheaper than the count weighting of ray-tracing's surface area heuristic
/// (count x area), which assumes a cost per primitive in each leaf (docs/scale.md §9).
double side_weight(double count) {
    // Small counts from a table: the sweeps of small ranges price every cut, and log2 was 5 % of a small build.
    static const std::array<double, 65> small = [] {
        std::array<double, 65> weights{};
        for (std::size_t i = 1; i < weights.size(); ++i) weights[i] = 2.0 * std::log2(static_cast<double>(i));
        return weights;
    }();
    if (count >= 1.0 && count < static_cast<double>(small.size()) && count == std::floor(count))
        return small[static_cast<std::size_t>(count)];
    return 2.0 * std::log2(count);
}

/// A cut's expected Eq. 2, with the boxes' surface as the tie-breaker: flat scenes (every box of zero volume)
/// are then still cut where the sides are smallest.
struct CutCost {
    double volume = infinity;
    double area = infinity;
    [[nodiscard]] bool operator<(const CutCost& other) const {
        return volume != other.volume ? volume < other.volume : area < other.area;
    }
};

/// A primitive as the cuts see it, stored by value so that a range's passes read memory in order.
struct Ref {
    Aabb box;                         ///< The primitive's world box.
    Vec3 centre;
    std::span<const Sphere> spheres;  ///< The primitive's generating spheres (in the PrimitiveSet).
    std::uint32_t local = 0;
};

/// One node of the binary tree: a leaf (one primitive) or a cut of its range in two.
struct BinaryNode {
    Aabb box = Aabb::empty();
    std::uint32_t left = 0, right = 0;  ///< Inner nodes: the children's slots.
    std::uint32_t begin = 0, end = 0;   ///< The range of refs it covers.
    bool is_leaf = false;
};

/// Sums over sphere centres (count, sum, sum of outer products): added up, they give the covariance of any
/// union of ranges without visiting its spheres again.
struct Moments {
    double count = 0.0;
    Vec3 sum = Vec3::Zero();
    Mat3 outer = Mat3::Zero();
    void add(std::span<const Sphere> spheres) {
        for (const Sphere& s : spheres) {
            count += 1.0;
            sum += s.center;
            outer += s.center * s.center.transpose();
        }
    }
    void add(const Moments& other) {
        count += other.count;
        sum += other.sum;
        outer += other.outer;
    }
};

/// A node of the result: a kept binary node and its children (kept nodes or leaves), as slots.
struct WideNode {
    std::uint32_t slot = 0;
    std::uint32_t first_piece = 0;  ///< Its children are pieces_[first_piece, first_piece + piece_count).
    std::uint32_t piece_count = 0;
    BoundingVolume volume;
};

/// A proper rotation whose first column is the main axis of `covariance`, then the second.
Mat3 principal_axes(const Mat3& covariance) {
    Eigen::SelfAdjointEigenSolver<Mat3> solver;
    solver.computeDirect(covariance);
    Mat3 axes = Mat3::Identity();
    if (solver.info() != Eigen::Success || !solver.eigenvectors().allFinite()) return axes;
    const Vec3 x = solver.eigenvectors().col(2).normalized();
    Vec3 y = solver.eigenvectors().col(1) - solver.eigenvectors().col(1).dot(x) * x;
    if (!(y.norm() > 1e-9)) return axes;
    y.normalize();
    axes.col(0) = x;
    axes.col(1) = y;
    axes.col(2) = x.cross(y);
    return axes;
}

class BinnedBuilder {
public:
    /// `count_weighted_estimates`: the per-side sweeps of small inputs weight each side by its primitive count
    /// instead of side_weight (build_binned tries both there); `progress_offset`: added to every progress step.
    BinnedBuilder(const PrimitiveSet& set, const BinnedOptions& options, const detail::Checkpoint& checkpoint,
                  bool count_weighted_estimates, double progress_offset)
        : set_(set), options_(options), checkpoint_(checkpoint), count_weighted_estimates_(count_weighted_estimates),
          progress_offset_(progress_offset),
          max_children_(std::clamp(options.max_children, 2u, max_children_limit)), refs_(set.size()),
          nodes_(2 * std::size_t{set.size()} - 1), split_(nodes_.size() * (max_children_ + 1), 0) {
        tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, set.size(), 4096), [&](const tbb::blocked_range<std::uint32_t>& r) {
            for (std::uint32_t i = r.begin(); i < r.end(); ++i) {
                refs_[i].box = fit_aabb(set.spheres(i));
                refs_[i].centre = set.centre(i);
                refs_[i].spheres = set.spheres(i);
                refs_[i].local = i;
            }
        });
        depth_limit_ = static_cast<std::uint32_t>(2.0 * std::log2(static_cast<double>(set.size()) + 1.0)) + 32;
        const VolumePolicy& policy = set.policy();
        box_weight_ = policy.is_allowed(BvType::aabb) ? policy.weight_of(BvType::aabb) : 1.0;
        measure_ = policy.measure;
        needs_moments_ = policy.is_allowed(BvType::obb) || policy.is_allowed(BvType::capsule);
    }

    /// The hierarchy over `primitives` (the PrimitiveSet's input, in input order).
    Bvh build(std::span<const Primitive> primitives) {
        const std::uint32_t root = plan(0, static_cast<std::uint32_t>(refs_.size()), 0).slot;
        Bvh bvh;
        detail::reserve_on_huge_pages(bvh.primitives, primitives.size());
        bvh.primitives.assign(primitives.begin(), primitives.end());
        if (nodes_[root].is_leaf) {
            bvh.nodes.push_back(Node{primitives[set_.input_index(refs_[0].local)].volume, 0, 0, set_.input_index(refs_[0].local)});
            return bvh;
        }
        LargeVector<WideNode> wide;
        wide.reserve(refs_.size() - 1);  // at most one kept node per binary inner node; no regrowth
        pieces_.reserve(2 * refs_.size() - 2);
        collect(root, split_of(root)[1], wide);
        LargeVector<std::uint8_t>().swap(split_);  // the collapse is decided
        LargeVector<std::uint32_t> wide_of_slot(nodes_.size(), 0);
        for (std::uint32_t i = 0; i < wide.size(); ++i) wide_of_slot[wide[i].slot] = i;
        fit_all(wide, wide_of_slot);
        LargeVector<Moments>().swap(moments_);  // the fits are done: a twelfth of the memory, freed before the layout
        lay_out(wide, wide_of_slot, bvh);
        return bvh;
    }

private:
    /// Leaves take the first n slots (plan), so a slot says what it holds without reading the node.
    [[nodiscard]] bool is_leaf_slot(std::uint32_t slot) const { return slot < refs_.size(); }
    [[nodiscard]] std::uint8_t* split_of(std::uint32_t slot) { return split_.data() + std::size_t{slot} * (max_children_ + 1); }

    // Step 1: the binary tree, top-down.

    /// A planned subtree: its root's slot and collapse costs. The costs are needed only by the parent, so they
    /// travel up the recursion instead of living in an array over every node (144 MB at 10^6 primitives).
    struct Planned {
        std::uint32_t slot = 0;
        CollapseCosts costs{};
    };

    /// Slots as in split: the leaf at ref position i in slot i, the inner node that cuts before position c
    /// in slot n - 1 + c; so a node's slot depends on its range only, never on the thread that made it.
    Planned plan(std::uint32_t begin, std::uint32_t end, std::uint32_t depth) {
        if (end - begin == 1) {
            nodes_[begin] = BinaryNode{refs_[begin].box, 0, 0, begin, end, true};
            placed_.fetch_add(1, std::memory_order_relaxed);
            Planned leaf{begin, {}};
            leaf.costs.fill(infinity);
            leaf.costs[1] = 0.0;  // a leaf is one child of whichever node it ends up under
            return leaf;
        }
        checkpoint_.step(progress_offset_ + static_cast<double>(placed_.load(std::memory_order_relaxed)));
        const std::span<Ref> range(refs_.data() + begin, end - begin);
        const std::uint32_t cut = begin + (looks_ahead(range.size(), depth) ? lookahead_cut(range, depth) : choose_cut(range, depth));
        Planned left, right;
        constexpr std::uint32_t parallel_above = 4096;  // below, a task costs more than the range
        if (end - begin > parallel_above)
            tbb::parallel_invoke([&] { left = plan(begin, cut, depth + 1); }, [&] { right = plan(cut, end, depth + 1); });
        else
            left = plan(begin, cut, depth + 1), right = plan(cut, end, depth + 1);
        const auto slot = static_cast<std::uint32_t>(refs_.size()) - 1 + cut;
        nodes_[slot] = BinaryNode{nodes_[left.slot].box.merged(nodes_[right.slot].box), left.slot, right.slot, begin, end, false};
        return {slot, collapse_costs(slot, left.costs, right.costs)};
    }

    /// plan()'s subtree over a range, priced without building it: its collapse costs, with every cut chosen as
    /// choose_cut would choose it, found on lists of the range's positions sorted once along each axis instead of
    /// on refs re-sorted at every level. The look-ahead's trials (lookahead_cut).
    class SweptTrial {
    public:
        SweptTrial(const BinnedBuilder& builder, std::span<const Ref> range) : builder_(builder), range_(range) {
            const auto size = static_cast<std::uint32_t>(range.size());
            for (int axis = 0; axis < 3; ++axis) {
                std::vector<std::uint32_t>& list = sorted_[axis];
                list.resize(size);
                for (std::uint32_t i = 0; i < size; ++i) list[i] = i;
                std::sort(list.begin(), list.end(), [&](std::uint32_t a, std::uint32_t b) {
                    const double ca = range[a].centre[axis], cb = range[b].centre[axis];
                    return ca != cb ? ca < cb : range[a].local < range[b].local;
                });
            }
            side_.resize(size);
            scratch_.resize(size);
            right_sides_.resize(size);
            for (const Ref& ref : range) whole_ = whole_.merged(ref.box);
        }

        /// Every cut of the whole range priced as sweep_cut prices it: (cost, axis, left count), in sweep order.
        /// The left side of a cut is the first `left count` refs sorted along its axis.
        [[nodiscard]] std::vector<std::tuple<CutCost, int, std::uint32_t>> root_cuts() {
            std::vector<std::tuple<CutCost, int, std::uint32_t>> cuts;
            for (int axis = 0; axis < 3; ++axis)
                sweep(std::span(sorted_[axis]), [&](std::uint32_t left, const CutCost& cost) { cuts.emplace_back(cost, axis, left); });
            return cuts;
        }

        /// choose_cut's cut of the whole range at `depth`.
        [[nodiscard]] std::pair<int, std::uint32_t> greedy_cut(std::uint32_t depth) {
            return choice({std::span(sorted_[0]), std::span(sorted_[1]), std::span(sorted_[2])}, depth);
        }

        /// The least Eq. 2 cost of the range's subtree when its root is kept (collapse_costs' entry 1, the root's
        /// own term included) if it is cut along `axis` before `left`, each side planned as plan() plans it.
        [[nodiscard]] double kept_cost(int axis, std::uint32_t left, std::uint32_t depth) {
            std::array<std::vector<std::uint32_t>, 3> lists = sorted_;
            std::array<std::span<std::uint32_t>, 3> spans{std::span(lists[0]), std::span(lists[1]), std::span(lists[2])};
            const auto [left_costs, right_costs] = cut_and_plan(spans, axis, left, depth + 1);
            return builder_.combine(left_costs, right_costs, whole_, nullptr)[1];
        }

    private:
        /// Calls visit(left count, cost) for every cut of `list` (positions sorted along one axis).
        template <class Visit>
        void sweep(std::span<const std::uint32_t> list, Visit&& visit) {
            builder_.price_cuts(list.size(), [&](std::size_t i) -> const Aabb& { return range_[list[i]].box; },
                                right_sides_, visit);
        }

        /// The collapse costs of the sub-range whose positions are in `lists` (one list per axis, each sorted).
        CollapseCosts plan_costs(std::array<std::span<std::uint32_t>, 3> lists, std::uint32_t depth) {
            const std::size_t count = lists[0].size();
            if (count == 1) {
                CollapseCosts leaf;
                leaf.fill(infinity);
                leaf[1] = 0.0;
                return leaf;
            }
            const auto [best_axis, best_left] = choice(lists, depth);
            Aabb whole = Aabb::empty();
            for (const std::uint32_t i : lists[0]) whole = whole.merged(range_[i].box);
            const auto [left_costs, right_costs] = cut_and_plan(lists, best_axis, best_left, depth + 1);
            return builder_.combine(left_costs, right_costs, whole, nullptr);
        }

        /// choose_cut's choice for the sub-range in `lists`, as (axis, left count): median_cut beyond the depth
        /// limit, sweep_cut up to sweep_max_primitives, else binned_cut, else median_cut (estimate sweeps are off
        /// where looks_ahead allows a look-ahead).
        [[nodiscard]] std::pair<int, std::uint32_t> choice(const std::array<std::span<std::uint32_t>, 3>& lists,
                                                           std::uint32_t depth) {
            const std::size_t count = lists[0].size();
            if (depth < builder_.depth_limit_ && count <= builder_.options_.sweep_max_primitives) {
                CutCost best;
                std::pair<int, std::uint32_t> chosen{0, static_cast<std::uint32_t>(count / 2)};
                for (int axis = 0; axis < 3; ++axis)
                    sweep(lists[static_cast<std::size_t>(axis)], [&](std::uint32_t left, const CutCost& cost) {
                        if (cost < best) best = cost, chosen = {axis, left};  // ties: the earlier axis and cut
                    });
                return chosen;
            }
            if (depth < builder_.depth_limit_) {
                const BinnedChoice bins = builder_.binned_choice([&](auto&& visit) {
                    for (const std::uint32_t i : lists[0]) visit(range_[i]);
                });
                if (bins.axis != 3) {
                    std::uint32_t left = 0;
                    for (const std::uint32_t i : lists[0]) left += bins.left_of(range_[i]) ? 1u : 0u;
                    return {static_cast<int>(bins.axis), left};
                }
            }
            // median_cut: the lower half along the centres' longest extent.
            Vec3 extent;
            for (int axis = 0; axis < 3; ++axis)
                extent[axis] = range_[lists[static_cast<std::size_t>(axis)].back()].centre[axis] -
                               range_[lists[static_cast<std::size_t>(axis)].front()].centre[axis];
            int axis = 0;
            extent.maxCoeff(&axis);
            return {axis, static_cast<std::uint32_t>(count / 2)};
        }

        /// Splits every list into the first `left` positions along `axis` and the rest, each part keeping its
        /// order, and plans both parts.
        std::pair<CollapseCosts, CollapseCosts> cut_and_plan(std::array<std::span<std::uint32_t>, 3> lists, int axis,
                                                             std::uint32_t left, std::uint32_t depth) {
            const std::size_t count = lists[0].size();
            for (std::size_t i = 0; i < count; ++i) side_[lists[static_cast<std::size_t>(axis)][i]] = i < left;
            for (std::span<std::uint32_t> list : lists) {
                std::size_t l = 0, r = left;
                for (const std::uint32_t i : list) scratch_[side_[i] ? l++ : r++] = i;
                std::copy(scratch_.begin(), scratch_.begin() + static_cast<std::ptrdiff_t>(count), list.begin());
            }
            const CollapseCosts left_costs =
                plan_costs({lists[0].first(left), lists[1].first(left), lists[2].first(left)}, depth);
            const CollapseCosts right_costs =
                plan_costs({lists[0].subspan(left), lists[1].subspan(left), lists[2].subspan(left)}, depth);
            return {left_costs, right_costs};
        }

        const BinnedBuilder& builder_;
        std::span<const Ref> range_;
        std::array<std::vector<std::uint32_t>, 3> sorted_;
        std::vector<std::uint8_t> side_;
        std::vector<std::uint32_t> scratch_;
        std::vector<Aabb> right_sides_;
        Aabb whole_ = Aabb::empty();  ///< The range's box, the root's of every trial.
    };

    /// Whether plan() looks ahead at a range: near the top of small inputs, where one greedy cut decides the
    /// shape of the whole tree, and only where no estimate sweep is made below (SweptTrial reproduces the others).
    [[nodiscard]] bool looks_ahead(std::size_t size, std::uint32_t depth) const {
        return depth < options_.lookahead_depth && options_.lookahead_candidates > 0 &&
               refs_.size() > options_.estimate_sweep_up_to && size <= lookahead_max_primitives && size > 2 &&
               depth < depth_limit_;
    }

    /// The cut whose two sides, each planned greedily below, give the range the least collapsed box cost (the
    /// cost plan() will compute for it), among choose_cut's own (so the range's box cost is never above the
    /// greedy cut's) and the `lookahead_candidates` cheapest local minima of sweep_cut's price along each axis.
    /// The range is left sorted for it. On the Tie-Interceptor the greedy cut groups the blade tips and cannons
    /// of both wings, which no later re-arrangement undoes; a trial costs a few microseconds at 40 primitives
    /// (docs/fast.md).
    std::uint32_t lookahead_cut(std::span<Ref> range, std::uint32_t depth) const {
        SweptTrial trial(*this, range);
        // The candidates are the local minima of the price along each axis's sweep, cheapest first: the cuts
        // next to a minimum (one primitive more or fewer on a side) make nearly the same tree, and trials of the
        // eight cheapest cuts overall found less than trials of the six cheapest minima (docs/fast.md).
        const std::vector<std::tuple<CutCost, int, std::uint32_t>> priced = trial.root_cuts();
        std::vector<std::tuple<CutCost, int, std::uint32_t>> minima;
        for (std::size_t i = 0; i < priced.size(); ++i) {
            const auto& [price, axis, left] = priced[i];
            const bool first_of_axis = i == 0 || std::get<1>(priced[i - 1]) != axis;
            const bool last_of_axis = i + 1 == priced.size() || std::get<1>(priced[i + 1]) != axis;
            if ((first_of_axis || !(std::get<0>(priced[i - 1]) < price)) && (last_of_axis || price < std::get<0>(priced[i + 1])))
                minima.push_back(priced[i]);
        }
        // Ties: the sweep's order (the earlier axis and cut), as sweep_cut breaks them.
        std::stable_sort(minima.begin(), minima.end(), [](const auto& a, const auto& b) { return std::get<0>(a) < std::get<0>(b); });
        std::vector<std::pair<int, std::uint32_t>> candidates{trial.greedy_cut(depth)};
        for (std::size_t i = 0; i < minima.size() && candidates.size() <= options_.lookahead_candidates; ++i) {
            const std::pair<int, std::uint32_t> cut{std::get<1>(minima[i]), std::get<2>(minima[i])};
            if (cut != candidates.front()) candidates.push_back(cut);
        }
        double best = infinity;
        std::pair<int, std::uint32_t> chosen = candidates.front();
        for (const auto& [axis, left] : candidates) {
            const double kept = trial.kept_cost(axis, left, depth);
            if (kept < best) best = kept, chosen = {axis, left};
        }
        sort_along(range, chosen.first);
        return chosen.second;
    }

    /// Reorders `range` so that the cut falls before the returned position (0 < cut < size).
    std::uint32_t choose_cut(std::span<Ref> range, std::uint32_t depth) const {
        if (depth >= depth_limit_) return median_cut(range);
        if (refs_.size() <= options_.estimate_sweep_up_to && range.size() <= estimate_sweep_max_primitives)
            return estimate_sweep_cut(range);
        if (range.size() <= options_.sweep_max_primitives) return sweep_cut(range);
        if (const std::uint32_t cut = binned_cut(range); cut != 0) return cut;
        return median_cut(range);
    }

    /// Every cut of the centres sorted along x, y and z; the range is left sorted along the best axis.
    std::uint32_t sweep_cut(std::span<Ref> range) const {
        const std::size_t count = range.size();
        std::vector<Aabb> right_sides(count);
        CutCost best;
        int best_axis = 0;
        std::size_t best_cut = count / 2;
        for (int axis = 0; axis < 3; ++axis) {
            sort_along(range, axis);
            price_cuts(count, [&](std::size_t i) -> const Aabb& { return range[i].box; }, right_sides,
                       [&](std::uint32_t left, const CutCost& cost) {
                           if (cost < best) best = cost, best_axis = axis, best_cut = left;  // ties: the earlier axis and cut
                       });
        }
        if (best_axis != 2) sort_along(range, best_axis);
        return static_cast<std::uint32_t>(best_cut);
    }

    /// Calls visit(left count, cost) for every cut of `count` primitives in order, the i-th's box being box_at(i):
    /// each side's box grows by one primitive per cut (`right_sides` is scratch of at least `count`). sweep_cut's
    /// pricing, shared with the look-ahead's trials so that both price every cut alike.
    template <class BoxAt, class Visit>
    void price_cuts(std::size_t count, BoxAt&& box_at, std::vector<Aabb>& right_sides, Visit&& visit) const {
        Aabb running = Aabb::empty();
        for (std::size_t i = count; i-- > 0;) right_sides[i] = running = running.merged(box_at(i));
        running = Aabb::empty();
        for (std::size_t left = 1; left < count; ++left) {
            running = running.merged(box_at(left - 1));
            visit(static_cast<std::uint32_t>(left),
                  cut_cost(static_cast<double>(left), running, static_cast<double>(count - left), right_sides[left]));
        }
    }

    [[nodiscard]] double estimate_weight(double count) const { return count_weighted_estimates_ ? count : side_weight(count); }

    /// As sweep_cut, but each side priced as split prices its small nodes: the pricing fitter around that side
    /// alone (detail::PrimitiveSet::estimate: exact AABB and sphere, OBBs and capsules in the side's own
    /// frames), so a cut is chosen for the kinds the sides will have. O(m^2) fits per range: small inputs only.
    std::uint32_t estimate_sweep_cut(std::span<Ref> range) const {
        const std::size_t count = range.size();
        std::vector<std::uint32_t> locals(count);
        std::vector<double> right_sides(count);
        CutCost best;
        int best_axis = 0;
        std::size_t best_cut = count / 2;
        for (int axis = 0; axis < 3; ++axis) {
            sort_along(range, axis);
            for (std::size_t i = 0; i < count; ++i) locals[i] = range[i].local;
            const std::span<const std::uint32_t> all(locals);
            for (std::size_t i = 1; i < count; ++i) right_sides[i] = set_.estimate(all.subspan(i));
            for (std::size_t left = 1; left < count; ++left) {
                const double wl = estimate_weight(static_cast<double>(left)), wr = estimate_weight(static_cast<double>(count - left));
                const CutCost cost{wl * set_.estimate(all.first(left)) + wr * right_sides[left], 0.0};
                if (cost < best) best = cost, best_axis = axis, best_cut = left;  // ties: the earlier axis and cut
            }
        }
        if (best_axis != 2) sort_along(range, best_axis);
        return static_cast<std::uint32_t>(best_cut);
    }

    /// The best boundary between `bin_count` equal bins of the centres' extent on any axis, with the range
    /// partitioned there; 0 when the centres fall into one bin on every axis.
    std::uint32_t binned_cut(std::span<Ref> range) const {
        const BinnedChoice choice = binned_choice([&](auto&& visit) {
            for (const Ref& ref : range) visit(ref);
        });
        if (choice.axis == 3) return 0;
        // std::partition's result depends only on the range's contents and order, never on threads.
        const auto middle = std::partition(range.begin(), range.end(), [&](const Ref& ref) { return choice.left_of(ref); });
        return static_cast<std::uint32_t>(middle - range.begin());
    }

    /// binned_cut's choice: the axis (3 when the centres fall into one bin on every axis) and the boundary between
    /// bins, with what it takes to say on which side a ref falls. A ref's bin grows with its centre's coordinate,
    /// so the left side is a prefix of the refs sorted along the axis.
    struct BinnedChoice {
        std::size_t axis = 3;
        std::uint32_t boundary = 0;
        std::uint32_t bins = 0;
        Vec3 low = Vec3::Zero();
        std::array<double, 3> scale{};
        [[nodiscard]] std::uint32_t bin_index(const Ref& ref, std::size_t along) const {
            const auto a = static_cast<Eigen::Index>(along);
            const double at = (ref.centre[a] - low[a]) * scale[along];
            if (!(at > 0.0)) return 0u;  // NaN too: 0 x inf, a centre at the minimum of a denormal extent
            return static_cast<std::uint32_t>(std::min(at, static_cast<double>(bins - 1)));
        }
        [[nodiscard]] bool left_of(const Ref& ref) const { return bin_index(ref, axis) < boundary; }
    };

    /// binned_cut's choice over the refs that `for_each(visit)` visits.
    template <class ForEach>
    BinnedChoice binned_choice(ForEach&& for_each) const {
        Aabb centres = Aabb::empty();
        for_each([&](const Ref& ref) { centres = centres.merged({ref.centre, ref.centre}); });
        BinnedChoice choice;
        const std::uint32_t bins = choice.bins = std::clamp(options_.bin_count, 2u, 256u);
        choice.low = centres.min;
        struct Bin {
            Aabb box = Aabb::empty();
            double count = 0;
        };
        std::vector<Bin> bin(3 * std::size_t{bins});
        std::array<double, 3>& scale = choice.scale;
        for (std::size_t axis = 0; axis < 3; ++axis) {
            const double extent = centres.max[static_cast<Eigen::Index>(axis)] - centres.min[static_cast<Eigen::Index>(axis)];
            scale[axis] = extent > 0.0 ? static_cast<double>(bins) / extent : 0.0;
        }
        for_each([&](const Ref& ref) {
            for (std::size_t axis = 0; axis < 3; ++axis) {
                if (scale[axis] == 0.0) continue;
                Bin& b = bin[axis * bins + choice.bin_index(ref, axis)];
                b.box = b.box.merged(ref.box);
                b.count += 1.0;
            }
        });
        CutCost best;
        std::vector<Aabb> right_sides(bins);
        std::vector<double> right_counts(bins);
        for (std::size_t axis = 0; axis < 3; ++axis) {
            if (scale[axis] == 0.0) continue;
            const Bin* b = bin.data() + axis * bins;
            Aabb running = Aabb::empty();
            double count = 0;
            for (std::uint32_t i = bins; i-- > 0;) {
                running = running.merged(b[i].box);
                count += b[i].count;
                right_sides[i] = running;
                right_counts[i] = count;
            }
            running = Aabb::empty();
            count = 0;
            for (std::uint32_t boundary = 1; boundary < bins; ++boundary) {
                running = running.merged(b[boundary - 1].box);
                count += b[boundary - 1].count;
                if (count == 0 || right_counts[boundary] == 0) continue;
                const CutCost cost = cut_cost(count, running, right_counts[boundary], right_sides[boundary]);
                if (cost < best) best = cost, choice.axis = axis, choice.boundary = boundary;
            }
        }
        return choice;
    }

    /// Cuts are priced by the sides' world boxes whatever kinds are allowed: pricing OBBs and capsules in the
    /// range's principal frame as well (as split does) gave no cheaper trees in the end (the kept nodes' own
    /// fits decide their kinds) and cost 15 % of the build at 10^6 primitives (docs/scale.md §9).
    [[nodiscard]] CutCost cut_cost(double left_count, const Aabb& left, double right_count, const Aabb& right) const {
        const double wl = side_weight(left_count), wr = side_weight(right_count);
        return {wl * box_measure(left) + wr * box_measure(right), wl * box_area(left) + wr * box_area(right)};
    }

    /// A box as the policy measures a node: its volume, or under the calibrated objective its
    /// self_minkowski_volume (the volume path stays a plain product: it runs for every bin of every cut).
    [[nodiscard]] double box_measure(const Aabb& box) const {
        return measure_ == NodeMeasure::volume ? box.volume() : self_minkowski_volume(box);
    }

    /// The median along the centres' longest extent (ties by local index): balanced whatever the input.
    static std::uint32_t median_cut(std::span<Ref> range) {
        Aabb centres = Aabb::empty();
        for (const Ref& ref : range) centres = centres.merged({ref.centre, ref.centre});
        int axis = 0;
        (centres.max - centres.min).maxCoeff(&axis);
        const auto middle = range.begin() + static_cast<std::ptrdiff_t>(range.size() / 2);
        std::nth_element(range.begin(), middle, range.end(), [axis](const Ref& a, const Ref& b) {
            return a.centre[axis] != b.centre[axis] ? a.centre[axis] < b.centre[axis] : a.local < b.local;
        });
        return static_cast<std::uint32_t>(range.size() / 2);
    }

    /// Sorts by the centres along `axis`, ties by local index (a total order, so one result however sorted):
    /// 16-byte keys are sorted and the refs moved once, which is cheaper than sorting the refs themselves.
    static void sort_along(std::span<Ref> range, int axis) {
        struct Key {
            double at;
            std::uint32_t local, position;
        };
        thread_local std::vector<Key> keys;
        thread_local std::vector<Ref> sorted;
        keys.resize(range.size());
        for (std::size_t i = 0; i < range.size(); ++i)
            keys[i] = {range[i].centre[axis], range[i].local, static_cast<std::uint32_t>(i)};
        std::sort(keys.begin(), keys.end(),
                  [](const Key& a, const Key& b) { return a.at != b.at ? a.at < b.at : a.local < b.local; });
        sorted.resize(range.size());
        for (std::size_t i = 0; i < range.size(); ++i) sorted[i] = range[keys[i].position];
        std::copy(sorted.begin(), sorted.end(), range.begin());
    }

    // Step 2: the collapse.

    // For each binary node v, best[k] (k = 1..max_children) is the least Eq. 2 cost below v's nearest kept
    // ancestor A that v's subtree adds when it makes k of A's children: k = 1 keeps v (its own volume once per
    // child it keeps, plus its subtree), k >= 2 dissolves v into k pieces from below it. What A pays for them,
    // k x volume(A), is added where A is known. split[k] records the left child's share of k, and split[1]
    // the number of children v keeps. A min-plus convolution per node, O(n x max_children^2) in all. The
    // volume priced is the node's box, the one volume known for every binary node without a fit; the kept
    // nodes are fitted afterwards (step 3), which only makes them smaller.
    CollapseCosts collapse_costs(std::uint32_t slot, const CollapseCosts& left, const CollapseCosts& right) {
        return combine(left, right, nodes_[slot].box, split_of(slot));
    }

    /// collapse_costs of a node with box `box` over subtrees with costs `left` and `right`; records the choices
    /// in `split` unless it is null.
    [[nodiscard]] CollapseCosts combine(const CollapseCosts& left, const CollapseCosts& right, const Aabb& box,
                                        std::uint8_t* split) const {
        CollapseCosts best;
        best.fill(infinity);
        // Two pieces, one from each side, are always a valid choice: recorded first, so that where every price is
        // infinite (volumes that overflow) the pieces below still add up instead of recursing on a share of 0.
        if (split != nullptr) split[2] = 1;
        const std::uint32_t m = max_children_;
        for (std::uint32_t k = 2; k <= m; ++k)
            for (std::uint32_t i = 1; i < k; ++i) {
                const double cost = left[i] + right[k - i];
                if (cost < best[k]) {
                    best[k] = cost;
                    if (split != nullptr) split[k] = static_cast<std::uint8_t>(i);
                }
            }
        const double volume = box_weight_ * box_measure(box);
        double kept = infinity;
        std::uint8_t children = 2;
        for (std::uint32_t k = 2; k <= m; ++k) {
            const double cost = static_cast<double>(k) * volume + best[k];
            if (cost < kept) kept = cost, children = static_cast<std::uint8_t>(k);
        }
        best[1] = kept;
        if (split != nullptr) split[1] = children;
        return best;
    }

    /// Appends the slots of the `k` pieces of binary node `slot` (kept nodes or leaves), left to right.
    void pieces(std::uint32_t slot, std::uint32_t k, LargeVector<std::uint32_t>& out) {
        if (k == 1) {
            out.push_back(slot);
            return;
        }
        const std::uint32_t left_share = split_of(slot)[k];
        pieces(nodes_[slot].left, left_share, out);
        pieces(nodes_[slot].right, k - left_share, out);
    }

    /// The kept nodes below and at `slot` (kept with `k` children), children before parents. Their moments
    /// are summed later, in parallel, by fit_subtree (this walk is serial, and summing here was most of it).
    void collect(std::uint32_t slot, std::uint32_t k, LargeVector<WideNode>& wide) {
        WideNode node;
        node.slot = slot;
        node.first_piece = static_cast<std::uint32_t>(pieces_.size());
        pieces(nodes_[slot].left, split_of(slot)[k], pieces_);
        pieces(nodes_[slot].right, k - split_of(slot)[k], pieces_);
        node.piece_count = static_cast<std::uint32_t>(pieces_.size()) - node.first_piece;
        for (std::uint32_t p = node.first_piece; p < node.first_piece + node.piece_count; ++p) {
            const std::uint32_t child = pieces_[p];
            if (!nodes_[child].is_leaf) collect(child, split_of(child)[1], wide);
        }
        wide.push_back(node);
    }

    /// The moments of kept node `node` from its pieces, left to right: a leaf's spheres, a kept child's sum
    /// (already made: children are fitted first). The same additions in the same order whichever thread
    /// runs them, so the sums do not depend on the thread count.
    [[nodiscard]] Moments moments_of(const WideNode& node, const LargeVector<std::uint32_t>& wide_of_slot) const {
        Moments sum;
        for (std::uint32_t p = node.first_piece; p < node.first_piece + node.piece_count; ++p) {
            const std::uint32_t child = pieces_[p];
            if (nodes_[child].is_leaf)
                sum.add(refs_[nodes_[child].begin].spheres);
            else
                sum.add(moments_[wide_of_slot[child]]);
        }
        return sum;
    }

    // Step 3: one fit per kept node.

    /// Fits every kept node, children before parents (a node's hull fit uses its children's volumes), the
    /// subtrees of large nodes in parallel. Each volume depends on its subtree only, so on no thread count.
    void fit_all(LargeVector<WideNode>& wide, const LargeVector<std::uint32_t>& wide_of_slot) {
        if (needs_moments_) moments_.resize(wide.size());
        std::atomic<std::uint64_t> fitted{0};
        fit_subtree(static_cast<std::uint32_t>(wide.size() - 1), wide, wide_of_slot, fitted);
    }

    void fit_subtree(std::uint32_t index, LargeVector<WideNode>& wide, const LargeVector<std::uint32_t>& wide_of_slot,
                     std::atomic<std::uint64_t>& fitted) {
        WideNode& node = wide[index];
        const BinaryNode& binary = nodes_[node.slot];
        std::vector<std::uint32_t> inner;
        for (std::uint32_t p = node.first_piece; p < node.first_piece + node.piece_count; ++p)
            if (!nodes_[pieces_[p]].is_leaf) inner.push_back(wide_of_slot[pieces_[p]]);
        constexpr std::uint32_t parallel_above = 4096;  // primitives below a node worth a task per child
        if (binary.end - binary.begin > parallel_above)
            tbb::parallel_for(std::size_t{0}, inner.size(), [&](std::size_t i) { fit_subtree(inner[i], wide, wide_of_slot, fitted); });
        else
            for (const std::uint32_t child : inner) fit_subtree(child, wide, wide_of_slot, fitted);
        if (needs_moments_) moments_[index] = moments_of(node, wide_of_slot);
        node.volume = fit_node(node, wide, wide_of_slot, needs_moments_ ? moments_[index] : Moments{});
        const double n = static_cast<double>(refs_.size());
        const auto done = static_cast<double>(fitted.fetch_add(1, std::memory_order_relaxed) + 1);
        checkpoint_.step(progress_offset_ + n + n * done / static_cast<double>(wide.size()));
    }

    /// The smallest, by the policy's weights, of these enclosing volumes of the node's primitives:
    /// - the exact box; the box and the capsule on the main axis in the principal frame of the sphere centres
    ///   (from `moments`); the sphere around the box centre: one pass over the generating spheres;
    /// - boxes in DiTO's frames of those spheres (detail::dito_frames: extremal points along fixed directions,
    ///   no hull), where OBBs are allowed;
    /// - for nodes over at least `hull_fit_min_primitives`, fit_obb (hull-based) around its children's
    ///   volumes: it encloses them, so the primitives, and has a few dozen points however large the node is;
    /// - fit_best over the primitives, for nodes of at most `exact_fit_max_primitives`.
    BoundingVolume fit_node(const WideNode& wide_node, const LargeVector<WideNode>& wide,
                            const LargeVector<std::uint32_t>& wide_of_slot, const Moments& moments) const {
        const BinaryNode& node = nodes_[wide_node.slot];
        const VolumePolicy& policy = set_.policy();
        double best_volume = infinity;
        BoundingVolume best = node.box;
        auto consider = [&](BoundingVolume&& bv) {
            if (!policy.is_allowed(type_of(bv))) return;
            const double v = policy.weighted_volume(bv);
            if (v < best_volume) best_volume = v, best = std::move(bv);
        };
        consider(BoundingVolume(node.box));
        const bool want_obb = policy.is_allowed(BvType::obb);
        const bool want_frame = needs_moments_;
        const bool want_sphere = policy.is_allowed(BvType::sphere);
        const std::span<const Ref> range(refs_.data() + node.begin, node.end - node.begin);
        const std::size_t size = range.size();
        const bool hull_over_spheres = size >= options_.hull_fit_min_primitives && size <= options_.hull_fit_max_primitives &&
                                       refs_.size() <= options_.hull_fit_max_input;
        // A large node's children's volumes stand for its primitives: they enclose them, and their generating
        // spheres are a few dozen however many primitives lie below (the pass over all of them was a quarter
        // of the build at 10^6 primitives).
        const bool around_children = size >= options_.hull_fit_min_primitives && !hull_over_spheres;
        std::vector<Sphere> around;
        if (around_children)
            for (std::uint32_t p = wide_node.first_piece; p < wide_node.first_piece + wide_node.piece_count; ++p) {
                const BinaryNode& child = nodes_[pieces_[p]];
                append_generating_spheres(child.is_leaf ? set_.volume_of(refs_[child.begin].local)
                                                        : wide[wide_of_slot[pieces_[p]]].volume,
                                          around);
            }
        auto for_each_sphere = [&](auto&& visit) {
            if (around_children) {
                for (const Sphere& s : around) visit(s);
                return;
            }
            for (const Ref& ref : range)
                for (const Sphere& s : ref.spheres) visit(s);
        };
        if (want_frame || want_sphere) {
            const Vec3 origin = want_frame ? Vec3(moments.sum / moments.count) : node.box.center();
            const Mat3 axes =
                want_frame ? principal_axes(moments.outer / moments.count - origin * origin.transpose()) : Mat3::Identity();
            const Vec3 centre = node.box.center();
            Vec3 low = Vec3::Constant(infinity), high = Vec3::Constant(-infinity);
            double sphere_radius = 0.0, capsule_radius = 0.0, t_low = infinity, t_high = -infinity;
            for_each_sphere([&](const Sphere& s) {
                if (want_sphere) sphere_radius = std::max(sphere_radius, (s.center - centre).norm() + s.radius);
                if (!want_frame) return;
                const Vec3 local = axes.transpose() * (s.center - origin);
                low = low.cwiseMin(local - Vec3::Constant(s.radius));
                high = high.cwiseMax(local + Vec3::Constant(s.radius));
                capsule_radius = std::max(capsule_radius, std::sqrt(local.y() * local.y() + local.z() * local.z()) + s.radius);
                t_low = std::min(t_low, local.x());
                t_high = std::max(t_high, local.x());
            });
            if (want_sphere) consider(Sphere{centre, sphere_radius});
            if (want_frame) {
                consider(Obb{origin + axes * (0.5 * (low + high)), axes, 0.5 * (high - low)});
                const Vec3 u = axes.col(0);
                consider(Capsule{origin + t_low * u, origin + t_high * u, capsule_radius});
            }
        }
        const std::size_t dito_max = options_.dito_fit_max_primitives;
        if (want_obb && (size <= dito_max || hull_over_spheres)) {
            thread_local std::vector<Sphere> spheres;
            spheres.clear();
            for (const Ref& ref : range) spheres.insert(spheres.end(), ref.spheres.begin(), ref.spheres.end());
            if (size <= dito_max) {
                // Under the volume measure a frame whose box cannot beat the best so far is dropped after its
                // first pass, often after a few spheres (the same choice: `consider` keeps only a smaller one).
                // The margin covers the rounding of the volume and of the division.
                const bool can_bound = policy.measure == NodeMeasure::volume;
                for (const Mat3& frame : detail::dito_frames(spheres)) {
                    if (!can_bound) {
                        consider(detail::obb_with_axes(spheres, frame));
                        continue;
                    }
                    const double limit = best_volume / policy.weight_of(BvType::obb) * (1.0 + 1e-9);
                    if (std::optional<Obb> box = detail::obb_with_axes_below(spheres, frame, limit))
                        consider(std::move(*box));
                }
            }
            if (hull_over_spheres) consider(fit(BvType::obb, spheres));
        }
        if (want_obb && around_children) consider(fit(BvType::obb, around));
        if (range.size() <= options_.exact_fit_max_primitives || refs_.size() <= options_.exact_fit_all_up_to) {
            std::vector<std::uint32_t> locals;
            for (const Ref& ref : range) locals.push_back(ref.local);
            consider(set_.fit(locals));
        }
        return best;
    }

    // Step 4: the hierarchy.

    /// `wide` (children before parents, the root last) as `bvh.nodes`, breadth-first (a node's children are
    /// contiguous). Leaves carry their primitive's own volume. First the places, in one serial pass over
    /// indices; then the nodes are written on every core (2·10^6 nodes of 144 bytes at 10^6 primitives: the
    /// serial copy took 0.8 s of a 4 s build). Each node is written once, by its parent's task, whatever the
    /// thread count.
    void lay_out(LargeVector<WideNode>& wide, const LargeVector<std::uint32_t>& wide_of_slot, Bvh& bvh) const {
        // place[i]: wide node i's index in bvh.nodes; first_child[i]: where its children start.
        LargeVector<std::uint32_t> place(wide.size()), first_child(wide.size());
        {
            std::vector<std::uint32_t> queue{static_cast<std::uint32_t>(wide.size() - 1)};
            place[queue.front()] = 0;
            std::uint32_t next = 1;
            for (std::size_t q = 0; q < queue.size(); ++q) {
                const WideNode& node = wide[queue[q]];
                first_child[queue[q]] = next;
                for (std::uint32_t p = 0; p < node.piece_count; ++p) {
                    const std::uint32_t slot = pieces_[node.first_piece + p];
                    if (is_leaf_slot(slot)) continue;
                    place[wide_of_slot[slot]] = next + p;
                    queue.push_back(wide_of_slot[slot]);
                }
                next += node.piece_count;
            }
        }
        detail::reserve_on_huge_pages(bvh.nodes, wide.size() + refs_.size());
        bvh.nodes.resize(wide.size() + refs_.size());
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, wide.size(), 1024), [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t i = r.begin(); i < r.end(); ++i) {
                WideNode& node = wide[i];
                bvh.nodes[place[i]] = Node{std::move(node.volume), first_child[i], node.piece_count, 0};
                for (std::uint32_t p = 0; p < node.piece_count; ++p) {
                    const std::uint32_t slot = pieces_[node.first_piece + p];
                    if (!is_leaf_slot(slot)) continue;
                    const std::uint32_t primitive = set_.input_index(refs_[slot].local);  // a leaf's slot is its ref
                    bvh.nodes[first_child[i] + p] = Node{bvh.primitives[primitive].volume, 0, 0, primitive};
                }
            }
        });
    }

    const PrimitiveSet& set_;
    const BinnedOptions& options_;
    const detail::Checkpoint& checkpoint_;
    bool count_weighted_estimates_;
    double progress_offset_;
    std::uint32_t max_children_;
    std::uint32_t depth_limit_ = 0;
    double box_weight_ = 1.0;
    NodeMeasure measure_ = NodeMeasure::volume;
    bool needs_moments_ = false;               ///< Whether OBBs or capsules are fitted (they need a frame).
    LargeVector<std::uint32_t> pieces_;        ///< The kept nodes' children, as slots, node after node.
    LargeVector<Moments> moments_;             ///< Per kept node (as `wide`), when needs_moments_.
    std::atomic<std::uint64_t> placed_{0};  ///< Leaves made so far, for progress (any thread).
    LargeVector<Ref> refs_;                 ///< The primitives; each plan() reorders only its range.
    LargeVector<BinaryNode> nodes_;         ///< n leaves, then n - 1 inner nodes by their cut position.
    LargeVector<std::uint8_t> split_;       ///< (max_children + 1) collapse choices per node.
};

}  // namespace
}  // namespace binned_internal

Result<Bvh> build_binned(std::span<const Primitive> primitives, const BuildContext& context, const BinnedOptions& options) {
    const auto n = static_cast<double>(primitives.size());
    // Small inputs are built twice, their per-side sweeps weighting sides by log2 of their counts and by the
    // counts themselves, and keep the cheaper tree: on the 20 bundled and ../shared/data models neither
    // weighting is the better on all of them (docs/scale.md §9), and each build takes milliseconds there.
    const bool twice = primitives.size() <= options.estimate_sweep_up_to;
    return detail::guarded_build(primitives, context, "binned", (twice ? 4.0 : 2.0) * n, [&](const detail::Checkpoint& checkpoint) {
        std::vector<std::uint32_t> order(primitives.size());
        for (std::uint32_t i = 0; i < order.size(); ++i) order[i] = i;
        const detail::PrimitiveSet set(primitives, std::move(order), context.policy);
        Bvh tree = binned_internal::BinnedBuilder(set, options, checkpoint, false, 0.0).build(primitives);
        if (twice) {
            Bvh other = binned_internal::BinnedBuilder(set, options, checkpoint, true, 2.0 * n).build(primitives);
            if (cost(other, context.policy) < cost(tree, context.policy)) tree = std::move(other);
        }
        if (primitives.size() <= options.guarantee_split_up_to) {
            // split checks the deadline itself; if it runs out there, binned's tree stands.
            BuildContext split_context = context;
            split_context.report = nullptr;
            split_context.progress = nullptr;
            Result<Bvh> split = build_split(primitives, split_context);
            if (split && cost(*split, context.policy) < cost(tree, context.policy)) {
                tree = std::move(*split);
                if (context.report != nullptr)
                    context.report->notes.push_back("binned: split's tree was cheaper and is returned");
            }
        }
        return tree;
    });
}

}  // namespace hbvh
