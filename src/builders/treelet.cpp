// SPDX-License-Identifier: MIT
// Treelet refinement (docs/treelets.md), after Karras and Aila's treelet restructuring for ray-tracing
// BVHs (HPG 2013), here with Eq. 2 as the cost and the subset DP of optimal.cpp as the exact solver.
//
// Why a treelet can be solved exactly: fix an inner node N and a set of m disjoint subtrees ("units")
// that together cover N's primitives. Any tree over the units keeps each unit's internal cost, so its
// Eq. 2 cost is a constant plus the sum over its new inner nodes of children x vol(BV of the primitives
// below). That is exactly the problem solve_optimal_hierarchy solves with the units as its leaves, with
// subset_volume[mask] = weighted volume of the BV over the primitives of the units in mask.
#include "hbvh/builders/treelet.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <limits>
#include <unordered_map>
#include <utility>
#include <vector>

#include "hbvh/assert.hpp"
#include "hbvh/builders/optimal.hpp"
#include "optimal_plan.hpp"
#include "treelet_fit_cache.hpp"
#include "hbvh/fit/fit.hpp"
#include "hbvh/fit/fit_fast.hpp"
#include "../fit/staged_fit.hpp"
#include "hbvh/tree/stats.hpp"

namespace hbvh {
namespace {

using Clock = std::chrono::steady_clock;

/// A node of the mutable tree the refiner edits; ids are stable, replaced inner nodes become garbage.
struct Item {
    BoundingVolume volume;
    std::vector<std::uint32_t> children;
    std::uint32_t primitive = 0;
};

using Fitted = detail::TreeletFit;

/// What a fit waiting for its capsule step holds, roughly, for TreeletFitCache::pending_budget: its spheres twice
/// (its own copy and the proxy's) and a few kilobytes of hull, frames and hints.
constexpr std::size_t pending_bytes_per_sphere = 2 * sizeof(Sphere);
constexpr std::size_t pending_bytes_each = 8192;

class Refiner {
public:
    Refiner(const Bvh& bvh, const VolumePolicy& policy, const TreeletOptions& options, detail::TreeletFitCache& cache)
        : primitives_(bvh.primitives), policy_(policy),
          max_units_(std::clamp<std::uint32_t>(options.max_units, 2, optimal_hard_limit)), cache_(cache.fits),
          pending_budget_(cache.pending_budget),
          bounds_(cache.bounds), bound_scale_(detail::bound_scale(policy)), fitter_(cache.fitter()),
          bound_fits_(options.bound_fits && fitter_ == detail::TreeletFitter::best &&
                      (policy.is_allowed(BvType::obb) || policy.is_allowed(BvType::capsule))) {
        items_.reserve(bvh.nodes.size());
        for (const Node& node : bvh.nodes) {
            Item item{node.volume, {}, node.primitive};
            for (std::uint32_t c = 0; c < node.child_count; ++c) item.children.push_back(node.first_child + c);
            items_.push_back(std::move(item));
        }
    }

    /// Inner nodes below the root (id 0), children before parents.
    [[nodiscard]] std::vector<std::uint32_t> inner_postorder() const {
        std::vector<std::uint32_t> order;
        std::vector<std::pair<std::uint32_t, bool>> stack{{0u, false}};
        while (!stack.empty()) {
            const auto [id, visited] = stack.back();
            stack.pop_back();
            if (items_[id].children.empty()) continue;
            if (visited) {
                order.push_back(id);
                continue;
            }
            stack.emplace_back(id, true);
            for (auto it = items_[id].children.rbegin(); it != items_[id].children.rend(); ++it)
                stack.emplace_back(*it, false);
        }
        return order;
    }

    /// Solves the treelet rooted at `root`; true when it was replaced by a strictly cheaper one.
    bool refine_at(std::uint32_t root);

    [[nodiscard]] Bvh finish() const;
    [[nodiscard]] std::uint64_t fit_count() const { return fits_; }

private:
    /// The fit of one covered set by the cache's fitter; fit_best's may be short of its capsule step.
    [[nodiscard]] Fitted fit_set(std::span<const std::uint32_t> set) const {
        FitInput input;
        for (std::uint32_t p : set) input.add(primitives_[p].volume);
        if (fitter_ == detail::TreeletFitter::best) {
            detail::OwnedFit fit = detail::start_owned_fit(std::move(input.spheres), policy_, input.hint_axes);
            // Without the bounds every set is fitted completely, as before the fits on demand (the tests' reference);
            // so is every set once the waiting fits hold their budget.
            const auto charge =
                static_cast<std::int64_t>(pending_bytes_per_sphere * fit.spheres.size() + pending_bytes_each);
            bool wait = bound_fits_ && fit.stages.capsule_pending;
            if (wait && pending_budget_.fetch_sub(charge, std::memory_order_relaxed) < charge) {
                pending_budget_.fetch_add(charge, std::memory_order_relaxed);
                wait = false;
            }
            if (!wait) {
                fit.finish(policy_);
                return Fitted(std::move(*fit.stages.best), fit.stages.best_cost);
            }
            return Fitted(std::move(fit), policy_, pending_budget_, charge);
        }
        // fit_fast takes only a box hint's frame, so FitInput's distinct box frames stand in for the boxes; it
        // places a capsule along each capsule hint's line, so the distinct capsules go as they are.
        std::vector<BoundingVolume> hints;
        for (const Mat3& axes : input.hint_axes) hints.emplace_back(Obb{Vec3::Zero(), axes, Vec3::Zero()});
        for (std::uint32_t p : set) {
            const Capsule* capsule = std::get_if<Capsule>(&primitives_[p].volume);
            if (capsule == nullptr) continue;
            const bool repeat = std::any_of(hints.begin(), hints.end(), [&](const BoundingVolume& hint) {
                const Capsule* seen = std::get_if<Capsule>(&hint);
                return seen != nullptr && seen->p0 == capsule->p0 && seen->p1 == capsule->p1;
            });
            if (!repeat) hints.emplace_back(*capsule);
        }
        BoundingVolume bv = fit_fast(input.spheres, hints, policy_);
        const double weighted = policy_.weighted_volume(bv);
        return Fitted(std::move(bv), weighted);
    }

    /// Fits the sets of `masks` (keys[mask], sorted primitive indices) in parallel, each depending on its set
    /// only, so the result does not depend on the thread count; they go to the shared cache and to `fitted`.
    void fit_masks(std::span<const std::uint32_t> masks, std::span<const std::vector<std::uint32_t>> keys,
                   std::vector<const Fitted*>& fitted) {
        std::vector<Fitted> fresh(masks.size());
        const auto fit_range = [&](const tbb::blocked_range<std::size_t>& range) {
            for (std::size_t j = range.begin(); j != range.end(); ++j) fresh[j] = fit_set(keys[masks[j]]);
        };
        // One fit_best per task: a fit takes 0.1-0.6 ms, and a DP round needs only a few, so with larger chunks an
        // idle core (the last member refining, in auto) could not take any of them. The quick fitter's fits take
        // microseconds, a task's own cost, so it keeps chunks of four.
        const std::size_t grain = fitter_ == detail::TreeletFitter::best ? 1 : 4;
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, masks.size(), grain), fit_range);
        fits_ += masks.size();
        for (std::size_t j = 0; j < masks.size(); ++j) {
            // Another refinement sharing the cache may have inserted the same set meanwhile: its fit is identical
            // (same set, same primitives, same policy), so either copy will do.
            const auto it = cache_.emplace(keys[masks[j]], std::move(fresh[j])).first;
            fitted[masks[j]] = &it->second;  // the map never moves its elements
        }
    }

    /// Runs the pending capsule steps of the fits of `masks`, in parallel.
    void finish_masks(std::span<const std::uint32_t> masks, std::span<const Fitted* const> fitted) {
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, masks.size(), 1),
                          [&](const tbb::blocked_range<std::size_t>& range) {
                              for (std::size_t j = range.begin(); j != range.end(); ++j) fitted[masks[j]]->finish();
                          });
    }

    /// Sets known[mask] to the bound of the units in `mask` (sets keys[mask], or unit_primitives for one unit):
    /// from the shared cache, else built from the bounds of the mask without its lowest unit and of that unit
    /// (which the caller has made first: refine_at goes a unit count at a time), and cached.
    void make_bound(std::uint32_t mask, std::span<const std::vector<std::uint32_t>> keys,
                    std::span<const std::vector<std::uint32_t>> unit_primitives,
                    std::vector<const detail::SetBound*>& known) {
        const auto set_of = [&](std::uint32_t m) -> const std::vector<std::uint32_t>& {
            return std::popcount(m) == 1 ? unit_primitives[std::countr_zero(m)] : keys[m];
        };
        auto found = bounds_.find(set_of(mask));
        if (found == bounds_.end()) {
            detail::SetBound made;
            if (std::popcount(mask) == 1) {
                made = detail::bound_set(primitives_, set_of(mask), bound_scale_);
            } else {
                const std::uint32_t rest = mask & (mask - 1u);
                const std::uint32_t lowest = mask & ~rest;
                HBVH_ASSERT(known[rest] != nullptr && known[lowest] != nullptr);
                made = detail::bound_union(primitives_, *known[rest], set_of(rest), *known[lowest], set_of(lowest),
                                           bound_scale_);
            }
            found = bounds_.emplace(set_of(mask), std::move(made)).first;
        }
        known[mask] = &found->second;  // the map never moves its elements
    }

    [[nodiscard]] std::vector<std::uint32_t> covered(std::uint32_t id) const {
        std::vector<std::uint32_t> out;
        std::vector<std::uint32_t> stack{id};
        while (!stack.empty()) {
            const Item& item = items_[stack.back()];
            stack.pop_back();
            if (item.children.empty()) out.push_back(item.primitive);
            for (std::uint32_t child : item.children) stack.push_back(child);
        }
        std::sort(out.begin(), out.end());
        return out;
    }

    const std::vector<Primitive>& primitives_;
    const VolumePolicy& policy_;
    std::uint32_t max_units_;
    std::vector<Item> items_;
    detail::TreeletFitCache::Map& cache_;
    std::atomic<std::int64_t>& pending_budget_;
    detail::TreeletFitCache::BoundMap& bounds_;
    double bound_scale_;
    detail::TreeletFitter fitter_;
    bool bound_fits_;
    std::uint64_t fits_ = 0;
};

bool Refiner::refine_at(std::uint32_t root) {
    if (items_[root].children.size() > max_units_) return false;

    // Stage 1: the treelet. Expand the frontier unit with the largest weighted volume (the first on ties)
    // while the frontier stays within max_units: big volumes are where re-grouping pays most.
    std::vector<std::uint32_t> frontier = items_[root].children;
    std::vector<std::uint32_t> expanded{root};
    for (;;) {
        std::size_t chosen = frontier.size();
        double largest = -1.0;
        for (std::size_t i = 0; i < frontier.size(); ++i) {
            const Item& item = items_[frontier[i]];
            if (item.children.empty() || frontier.size() - 1 + item.children.size() > max_units_) continue;
            const double weighted = policy_.weighted_volume(item.volume);
            if (weighted > largest) {
                largest = weighted;
                chosen = i;
            }
        }
        if (chosen == frontier.size()) break;
        const std::uint32_t id = frontier[chosen];
        expanded.push_back(id);
        frontier.erase(frontier.begin() + static_cast<std::ptrdiff_t>(chosen));
        frontier.insert(frontier.begin() + static_cast<std::ptrdiff_t>(chosen), items_[id].children.begin(),
                        items_[id].children.end());
    }
    const auto units = static_cast<std::uint32_t>(frontier.size());
    if (units < 3) return false;  // two units admit one tree only

    // Stage 2: the current arrangement as masks over the units, and its cost.
    std::unordered_map<std::uint32_t, std::uint32_t> mask_of;
    for (std::uint32_t i = 0; i < units; ++i) mask_of[frontier[i]] = 1u << i;
    double current = 0.0;
    for (auto it = expanded.rbegin(); it != expanded.rend(); ++it) {  // children were expanded after parents
        std::uint32_t mask = 0;
        for (std::uint32_t child : items_[*it].children) mask |= mask_of.at(child);
        mask_of[*it] = mask;
        current += static_cast<double>(items_[*it].children.size()) * policy_.weighted_volume(items_[*it].volume);
    }

    // Stage 3: the covered set of every union of two or more units, and its fit where the cache has it.
    std::vector<std::vector<std::uint32_t>> unit_primitives(units);
    for (std::uint32_t i = 0; i < units; ++i) unit_primitives[i] = covered(frontier[i]);
    const std::uint32_t subsets = 1u << units;
    std::vector<const Fitted*> fitted(subsets, nullptr);
    std::vector<std::vector<std::uint32_t>> keys(subsets);
    std::vector<std::uint32_t> missing;
    for (std::uint32_t mask = 1; mask < subsets; ++mask) {
        if (std::popcount(mask) < 2) continue;
        // The union of the mask without its lowest unit (built before, a smaller mask) and that unit, merged.
        const std::uint32_t rest = mask & (mask - 1u);
        const std::vector<std::uint32_t>& lowest = unit_primitives[std::countr_zero(mask)];
        const std::vector<std::uint32_t>& others =
            std::popcount(rest) > 1 ? keys[rest] : unit_primitives[std::countr_zero(rest)];
        std::vector<std::uint32_t>& key = keys[mask];
        key.resize(lowest.size() + others.size());
        std::merge(lowest.begin(), lowest.end(), others.begin(), others.end(), key.begin());
        if (auto found = cache_.find(key); found != cache_.end())
            fitted[mask] = &found->second;
        else
            missing.push_back(mask);
    }

    // Stage 4: the subset volumes. Where the current tree already has a node over a set and its BV is
    // allowed and no larger than the fit, keep it: then the current arrangement is one of the DP's
    // candidates at its current cost, so the optimum can only be cheaper.
    std::vector<double> kept_volume(subsets, std::numeric_limits<double>::infinity());
    std::vector<std::uint32_t> kept_id(subsets, 0);  // item id + 1 of the current node over the set, 0 = none
    for (std::uint32_t id : expanded) {
        const std::uint32_t mask = mask_of.at(id);
        const BoundingVolume& bv = items_[id].volume;
        if (!policy_.is_allowed(type_of(bv))) continue;
        kept_volume[mask] = policy_.weighted_volume(bv);
        kept_id[mask] = id + 1;
    }
    std::vector<double> volume(subsets, 0.0);
    std::vector<std::uint32_t> keep(subsets, 0);  // item id + 1 whose BV to keep, 0 = use the fit
    std::vector<std::uint8_t> settled(subsets, 0);  // volume[mask] is what the tree would pay, not a lower bound
    const auto settle = [&](std::uint32_t mask) {
        // A fit short of its capsule step gives a lower bound; a kept volume at or below it is below the fit too.
        // known() first: another refinement may finish the fit meanwhile, and a value read after it is then the
        // answer or still the bound, either of them at most the answer, while `settled` says only what was known.
        const Fitted& fit = *fitted[mask];
        settled[mask] = fit.known();
        volume[mask] = fit.value();
        if (kept_volume[mask] <= volume[mask]) {
            volume[mask] = kept_volume[mask];
            keep[mask] = kept_id[mask];
            settled[mask] = 1;
        }
    };
    for (std::uint32_t mask = 1; mask < subsets; ++mask)
        if (fitted[mask] != nullptr) settle(mask);

    // The missing fits, on demand: each set stands in by a lower bound of its weighted volume (treelet_bounds.hpp)
    // until the DP's optimum uses it; then the optimum's missing sets are fitted and the DP solved again. An
    // optimum that uses fitted sets only is the optimum over the fits (every other tree costs at least its
    // bounds), and one no cheaper than the current tree proves that no fit would make it cheaper. So the answer
    // is the one of fitting every set (up to a choice between trees of equal cost), with fewer fits. Where a fit
    // costs about what a bound does (the quick fitter; fit_best without boxes and capsules), every set is fitted.
    if (bound_fits_ && !missing.empty()) {
        // A mask's bound is built from its lowest unit's and the rest's, so they are made a level (unit count) at a
        // time, each level's in parallel: the cache and `known` take concurrent writes to distinct masks.
        std::vector<const detail::SetBound*> known(subsets, nullptr);
        std::vector<std::vector<std::uint32_t>> by_level(units + 1);
        std::vector<std::uint8_t> wanted(subsets, 0);
        for (std::uint32_t mask : missing)
            for (std::uint32_t m = mask; m != 0 && !wanted[m]; m &= m - 1u) {
                wanted[m] = 1;
                by_level[static_cast<std::size_t>(std::popcount(m))].push_back(m);
                wanted[m & ~(m - 1u)] = 1;  // the lowest unit
            }
        for (std::uint32_t i = 0; i < units; ++i)
            if (wanted[1u << i]) make_bound(1u << i, keys, unit_primitives, known);
        for (std::size_t level = 2; level <= units; ++level)
            tbb::parallel_for(tbb::blocked_range<std::size_t>(0, by_level[level].size(), 2),
                              [&](const tbb::blocked_range<std::size_t>& range) {
                                  for (std::size_t j = range.begin(); j != range.end(); ++j)
                                      make_bound(by_level[level][j], keys, unit_primitives, known);
                              });
        for (std::uint32_t mask : missing) volume[mask] = std::min(known[mask]->bound, kept_volume[mask]);
    } else {
        fit_masks(missing, keys, fitted);
        for (std::uint32_t mask : missing) settle(mask);
    }
    // The optimum over volumes that are lower bounds where not settled: it is the optimum over the fits once it
    // uses settled volumes only. Until then its sets without a fit are fitted, and its fits short of the capsule
    // step finished (each may then leave the optimum).
    OptimalPlan plan;
    for (;;) {
        plan = solve_optimal_hierarchy(units, volume);
        if (!(plan.cost < current * (1.0 - 1e-12))) return false;
        std::vector<std::uint32_t> needed;
        std::vector<std::uint32_t> unfinished;
        for (const OptimalGroup& group : plan.groups) {
            if (fitted[group.covered] == nullptr)
                needed.push_back(group.covered);
            else if (!settled[group.covered])
                unfinished.push_back(group.covered);
        }
        if (needed.empty() && unfinished.empty()) break;
        fit_masks(needed, keys, fitted);
        finish_masks(unfinished, fitted);
        for (std::uint32_t mask : needed) settle(mask);
        for (std::uint32_t mask : unfinished) settle(mask);
    }

    // Stage 5: rebuild the treelet, children before parents. The root keeps its id so that its parent
    // and the caller's postorder stay valid; the replaced inner nodes are left unreferenced.
    std::vector<std::uint32_t> id_of(subsets, 0);
    for (std::uint32_t i = 0; i < units; ++i) id_of[1u << i] = frontier[i];
    for (auto it = plan.groups.rbegin(); it != plan.groups.rend(); ++it) {
        const std::uint32_t mask = it->covered;
        BoundingVolume bv = keep[mask] != 0 ? items_[keep[mask] - 1].volume : fitted[mask]->volume();
        std::vector<std::uint32_t> children;
        for (std::uint32_t child : it->children) children.push_back(id_of[child]);
        if (mask == subsets - 1u) {
            items_[root].volume = std::move(bv);
            items_[root].children = std::move(children);
            id_of[mask] = root;
        } else {
            items_.push_back({std::move(bv), std::move(children), 0});
            id_of[mask] = static_cast<std::uint32_t>(items_.size() - 1);
        }
    }
    return true;
}

Bvh Refiner::finish() const {
    TreeAssembler assembler(primitives_);
    std::vector<std::uint32_t> assembled(items_.size(), 0);
    std::vector<std::pair<std::uint32_t, bool>> stack{{0u, false}};
    while (!stack.empty()) {
        const auto [id, visited] = stack.back();
        stack.pop_back();
        const Item& item = items_[id];
        if (item.children.empty()) {
            assembled[id] = assembler.add_leaf(item.primitive);
        } else if (visited) {
            std::vector<std::uint32_t> children;
            for (std::uint32_t child : item.children) children.push_back(assembled[child]);
            assembled[id] = assembler.add_group(children, item.volume);
        } else {
            stack.emplace_back(id, true);
            for (std::uint32_t child : item.children) stack.emplace_back(child, false);
        }
    }
    return std::move(assembler).finish(assembled[0]);
}

}  // namespace

Bvh refine_treelets(const Bvh& bvh, const VolumePolicy& policy, const TreeletOptions& options,
                    TreeletReport* report) {
    detail::TreeletFitCache cache(bvh.primitives.size());
    return detail::refine_treelets_cached(bvh, policy, options, cache, report);
}

Bvh detail::refine_treelets_cached(const Bvh& bvh, const VolumePolicy& policy, const TreeletOptions& options,
                                   TreeletFitCache& cache, TreeletReport* report) {
    HBVH_ASSERT(cache.primitive_count() == bvh.primitives.size());
    const auto start = Clock::now();
    TreeletReport local;
    if (bvh.nodes.size() < 2 || !validate_policy(policy)) {
        if (report != nullptr) *report = local;
        return bvh;
    }
    local.cost_before = cost(bvh, policy);
    Refiner refiner(bvh, policy, options, cache);
    for (std::uint32_t pass = 0; pass < options.max_passes && !local.time_limit_hit; ++pass) {
        bool changed = false;
        for (std::uint32_t id : refiner.inner_postorder()) {
            if (options.time_limit_seconds > 0.0 &&
                std::chrono::duration<double>(Clock::now() - start).count() > options.time_limit_seconds) {
                local.time_limit_hit = true;
                break;
            }
            ++local.treelets;
            if (refiner.refine_at(id)) {
                ++local.replaced;
                changed = true;
            }
        }
        ++local.passes;
        if (!changed) break;
    }
    Bvh refined = refiner.finish();
    local.fits = refiner.fit_count();
    local.cost_after = cost(refined, policy);
    if (report != nullptr) *report = local;
    return refined;
}

}  // namespace hbvh
