// SPDX-License-Identifier: MIT
// Internal: the fits treelet refinement makes, kept across refinements of different trees over the same
// primitives, so that auto's portfolio (one refinement per member) fits each covered set once.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include <tbb/concurrent_unordered_map.h>

#include "hbvh/assert.hpp"
#include "hbvh/builders/treelet.hpp"
#include "../fit/staged_fit.hpp"
#include "hbvh/geometry/bounding_volume.hpp"
#include "covered_set_fits.hpp"
#include "treelet_bounds.hpp"

namespace hbvh::detail {

/// The fit of one covered set and its weighted volume, or fit_best's stages short of a capsule step that may
/// still win (staged_fit.hpp): then only a lower bound is known until finish() runs that step. Most sets a
/// treelet's DP fits only refute a cheaper arrangement, and the bound usually does that as well (docs/treelets.md,
/// "The capsule on demand"). The answer is the same whichever thread finishes it, so sharing the fit is safe.
class TreeletFit {
public:
    TreeletFit() = default;
    /// A finished fit.
    TreeletFit(BoundingVolume volume, double weighted) : volume_(std::move(volume)), weighted_(weighted) {}
    /// fit_best's stages, short of their capsule step, under `policy` (copied: the refinement that made the fit may
    /// be over when another finishes it); the step holds `charge` of `budget` (TreeletFitCache::pending_budget),
    /// taken by the caller, until it has run.
    TreeletFit(OwnedFit fit, const VolumePolicy& policy, std::atomic<std::int64_t>& budget, std::int64_t charge) {
        HBVH_ASSERT(fit.stages.capsule_pending);
        weighted_ = fit.stages.lower_bound();
        pending_ = std::make_unique<Pending>();
        pending_->fit = std::move(fit);
        pending_->policy = policy;
        pending_->budget = &budget;
        pending_->charge = charge;
    }
    TreeletFit(TreeletFit&&) noexcept = default;
    TreeletFit& operator=(TreeletFit&& other) noexcept {
        if (this != &other) {
            give_back();
            volume_ = std::move(other.volume_);
            weighted_ = other.weighted_;
            pending_ = std::move(other.pending_);
        }
        return *this;
    }
    ~TreeletFit() { give_back(); }

    /// True when the answer is known: then value() is its weighted volume and volume() the volume.
    [[nodiscard]] bool known() const { return !pending_ || pending_->done.load(std::memory_order_acquire); }
    /// The answer's weighted volume when known(), else a lower bound of it.
    [[nodiscard]] double value() const { return known() && pending_ ? pending_->weighted : weighted_; }
    /// The answer. Precondition: known().
    [[nodiscard]] const BoundingVolume& volume() const { return pending_ ? pending_->volume : volume_; }
    /// Runs the pending step, once: a thread that asks meanwhile waits for it.
    void finish() const {
        if (!pending_) return;
        Pending& pending = *pending_;
        std::call_once(pending.once, [&] {
            pending.fit.finish(pending.policy);
            pending.weighted = pending.fit.stages.best_cost;
            pending.volume = std::move(*pending.fit.stages.best);
            pending.fit = {};  // the context and the spheres are not needed any more
            pending.budget->fetch_add(pending.charge, std::memory_order_relaxed);
            pending.done.store(true, std::memory_order_release);
        });
    }

private:
    /// A step that never ran gives its share of the budget back when its fit goes.
    void give_back() {
        if (pending_ && !pending_->done.load(std::memory_order_acquire))
            pending_->budget->fetch_add(pending_->charge, std::memory_order_relaxed);
    }

    struct Pending {
        std::once_flag once;
        std::atomic<bool> done{false};
        OwnedFit fit;
        VolumePolicy policy;
        std::atomic<std::int64_t>* budget = nullptr;
        std::int64_t charge = 0;
        BoundingVolume volume;  // the answer, once done
        double weighted = 0.0;
    };
    BoundingVolume volume_;  // the answer, when nothing was pending
    double weighted_ = 0.0;  // its weighted volume, or the lower bound while pending
    std::unique_ptr<Pending> pending_;
};

/// Which fitter a refinement prices its subsets with.
enum class TreeletFitter {
    best,  ///< fit_best: the tightest volumes, about 0.05-0.2 ms per set of a few dozen primitives.
    quick  ///< fit_fast, the set's distinct box frames and capsules as hints: microseconds, a little larger.
};

/// Fits by covered set (sorted input indices). A refinement's fit of a set depends on nothing but the set,
/// the primitives and the policy, so sharing the cache between refinements of trees built over the same
/// primitives (in input order, as every Bvh keeps them) under the same policy changes no result, even when
/// they run at the same time (auto refines its members in parallel): two threads that fit the same set
/// compute the same volume, and whichever inserts it first, the other finds an identical one. The map
/// inserts and finds concurrently and never moves an element, so pointers to fits stay valid.
class TreeletFitCache {
public:
    explicit TreeletFitCache(std::size_t primitive_count, TreeletFitter fitter = TreeletFitter::best)
        : primitive_count_(primitive_count), fitter_(fitter) {}
    [[nodiscard]] std::size_t primitive_count() const { return primitive_count_; }
    [[nodiscard]] TreeletFitter fitter() const { return fitter_; }
    using Map = tbb::concurrent_unordered_map<std::vector<std::uint32_t>, TreeletFit, CoveredSetHash>;
    Map fits;
    /// The lower bounds of the fits on demand (treelet_bounds.hpp), by covered set likewise. A set's bound may
    /// differ in its last bits by the union it was built from; a bound only decides which sets are fitted, and
    /// the tree is the optimum over the fits whichever they are (docs/treelets.md, "Fits on demand").
    using BoundMap = tbb::concurrent_unordered_map<std::vector<std::uint32_t>, SetBound, CoveredSetHash>;
    BoundMap bounds;
    /// Bytes, roughly, that fits waiting for their capsule step may hold at once (each its set's spheres and its
    /// fit context): a refinement of a large tree would otherwise keep them for every set it fitted. Past it, a fit
    /// runs its capsule step at once. Which fits wait changes no tree, only the work.
    static constexpr std::int64_t pending_budget_bytes = std::int64_t{32} << 20;
    std::atomic<std::int64_t> pending_budget{pending_budget_bytes};

private:
    std::size_t primitive_count_;
    TreeletFitter fitter_;
};

/// refine_treelets with fits looked up in, and added to, `cache`. Precondition: every tree refined with
/// one cache has the same primitives and is refined under the same policy. The report's `fits` counts the
/// fits this call made, not those it found (with refinements running at once, that count depends on timing;
/// the tree does not).
[[nodiscard]] Bvh refine_treelets_cached(const Bvh& bvh, const VolumePolicy& policy, const TreeletOptions& options,
                                         TreeletFitCache& cache, TreeletReport* report = nullptr);

}  // namespace hbvh::detail
