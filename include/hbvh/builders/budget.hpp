// SPDX-License-Identifier: MIT
// SolverBudget: how much search a set-partition solver may spend on one call (the bottom-up builders' knob).
#pragma once

#include <cstdint>

namespace hbvh {

/// Limits of one solver call; 0 means no limit. A node limit, unlike a time limit, keeps results
/// deterministic; the build's own deadline lives in BuildContext.
struct SolverBudget {
    std::uint64_t max_nodes = 0;   ///< Search-tree nodes.
    double max_seconds = 0.0;
};

}  // namespace hbvh
