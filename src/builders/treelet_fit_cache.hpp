// SPDX-License-Identifier: MIT
// Internal: the fits treelet refinement makes, kept across refinements of different trees over the same
// primitives, so that auto's portfolio (one refinement per member) fits each covered set once.
#pragma once

#include <cstdint>
#include <vector>

#include <tbb/concurrent_unordered_map.h>

#include "hbvh/builders/treelet.hpp"
#include "hbvh/geometry/bounding_volume.hpp"
#include "covered_set_fits.hpp"
#include "treelet_bounds.hpp"

namespace hbvh::detail {

/// fit_best over one covered set and its weighted volume.
struct TreeletFit {
    BoundingVolume volume;
    double weighted = 0.0;
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
