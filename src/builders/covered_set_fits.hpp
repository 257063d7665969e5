// SPDX-License-Identifier: MIT
// Internal: covered sets (the sorted primitive indices under a node) as keys, and the fits one build has made of
// them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "heuristic_support.hpp"

namespace hbvh::detail {

/// FNV-1a over the sorted primitive indices of a covered set.
struct CoveredSetHash {
    std::size_t operator()(const std::vector<std::uint32_t>& key) const {
        std::uint64_t h = 1469598103934665603ull;
        for (std::uint32_t v : key) {
            h ^= v;
            h *= 1099511628211ull;
        }
        return static_cast<std::size_t>(h);
    }
};

/// PrimitiveSet::fit of covered sets, each made once per build. The insertion builders refit a group whenever an
/// item moves in or out below it, and the same groups come back as items move back and trial moves are undone:
/// 21-46 % of their fits were repeats in auto on the bundled and ../shared models. A fit depends on the set
/// alone, so a repeat takes the stored volume and the trees are the same. Not thread-safe: one build's tree (and
/// the snapshots it takes of itself) use it from one thread.
class CoveredSetFits {
public:
    /// The fit of the primitives `sorted` (ascending local indices) of `set`.
    [[nodiscard]] BoundingVolume fit(const PrimitiveSet& set, std::vector<std::uint32_t>&& sorted) {
        if (const auto found = fits_.find(sorted); found != fits_.end()) return found->second;
        BoundingVolume volume = set.fit(sorted);
        // Keys take memory in proportion to the sets' sizes; past this many indices (16 MB) the rest are fitted
        // afresh, so a builder run on a very large input cannot grow the map without limit.
        if (stored_indices_ + sorted.size() <= max_stored_indices) {
            stored_indices_ += sorted.size();
            fits_.emplace(std::move(sorted), volume);
        }
        return volume;
    }

private:
    static constexpr std::size_t max_stored_indices = std::size_t{1} << 22;
    std::unordered_map<std::vector<std::uint32_t>, BoundingVolume, CoveredSetHash> fits_;
    std::size_t stored_indices_ = 0;
};

}  // namespace hbvh::detail
