// SPDX-License-Identifier: MIT
// build(): any registered builder by its Algorithm, with the shared checks; the entry point most programs need.
#pragma once

#include <span>

#include "hbvh/builders/auto.hpp"
#include "hbvh/builders/binned.hpp"
#include "hbvh/builders/bnb_enlarge.hpp"
#include "hbvh/builders/bnb_exact.hpp"
#include "hbvh/builders/bnb_tightest.hpp"
#include "hbvh/builders/context.hpp"
#include "hbvh/builders/fast.hpp"
#include "hbvh/builders/insertion.hpp"
#include "hbvh/builders/insertion_haber.hpp"
#include "hbvh/builders/merge.hpp"
#include "hbvh/builders/obbtree.hpp"
#include "hbvh/builders/optimal.hpp"
#include "hbvh/builders/registry.hpp"
#include "hbvh/builders/report.hpp"
#include "hbvh/builders/scale.hpp"
#include "hbvh/builders/split.hpp"
#include "hbvh/builders/treelet.hpp"
#include "hbvh/builders/two_level.hpp"
#include "hbvh/result.hpp"
#include "hbvh/tree/bvh.hpp"

namespace hbvh {

/// Ok when the primitives' world box has finite coordinates and a finite volume; otherwise an Error (no
/// file) saying the model must be scaled. Every builder checks this first: Eq. 2 is meaningless once
/// volumes overflow to infinity.
[[nodiscard]] Status check_finite_extent(std::span<const Primitive> primitives);

/// Builds a hierarchy over `primitives` with `algorithm`'s registered builder and its default options.
/// Every builder refuses an empty input, geometry that validate_primitives() refuses (naming the primitive)
/// and a model check_finite_extent() refuses, and never returns a tree that fails check_structure().
[[nodiscard]] Result<Bvh> build(std::span<const Primitive> primitives, Algorithm algorithm,
                                const BuildContext& context = {});

/// build(), then treelet refinement of the result (never costlier; docs/treelets.md) within the time the
/// build left (CLI --refine). For `auto`, whose own refinement is size-limited, it refines at any size.
[[nodiscard]] Result<Bvh> build_refined(std::span<const Primitive> primitives, Algorithm algorithm,
                                        const BuildContext& context, const TreeletOptions& treelets = {});

/// Appends a one-line summary of a treelet refinement to report.notes (and sets budget_hit on a time-out).
void note_treelets(BuildReport& report, const TreeletReport& treelets);
/// `treelets` with its time limit cut to what `context`'s deadline leaves (a token amount when none is left).
[[nodiscard]] TreeletOptions treelets_within(const BuildContext& context, TreeletOptions treelets);

}  // namespace hbvh
