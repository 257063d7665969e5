// SPDX-License-Identifier: MIT
// B&B-Tightest's candidate heuristic: greedy growth by Eq. 1 tightness (survey §3, Fig. 10).
#include <algorithm>
#include <limits>
#include <set>

#include "candidates.hpp"

namespace hbvh {

std::vector<std::vector<std::uint32_t>> tightest_candidates(const Level& level) {
    const std::uint32_t n = level.size();
    std::vector<std::vector<std::uint32_t>> sets;
    std::vector<std::uint32_t> grown;
    // The next growth step depends on the current set alone, so once a start's growth reaches a set that an
    // earlier start already grew through, the rest of its chain repeats that one: stop there. Same
    // candidates after duplicates are removed, far fewer fits (chains from mutual neighbours merge early).
    std::set<std::vector<std::uint32_t>> grown_through;
    for (std::uint32_t start = 0; start < n; ++start) {
        std::vector<std::uint32_t> group{start};
        std::vector<bool> in_group(n, false);
        in_group[start] = true;
        // Fig. 10: {a} -> {a,b} -> {a,b,c} -> ... -> the whole level, each step the tightest joint BV.
        while (group.size() < n) {
            std::uint32_t best = n;
            double best_tightness = std::numeric_limits<double>::infinity();
            for (std::uint32_t j = 0; j < n; ++j) {
                if (in_group[j]) continue;
                grown = group;
                grown.insert(std::upper_bound(grown.begin(), grown.end(), j), j);
                const double t = level.tightness(grown);
                // Strict '<' in canonical index order: ties go to the lowest index, independent of input order.
                if (best == n || t < best_tightness) {
                    best = j;
                    best_tightness = t;
                }
            }
            group.insert(std::upper_bound(group.begin(), group.end(), best), best);
            in_group[best] = true;
            if (!grown_through.insert(group).second) break;
            sets.push_back(group);
        }
    }
    return sets;
}

}  // namespace hbvh
