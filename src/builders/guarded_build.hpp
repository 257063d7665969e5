// SPDX-License-Identifier: MIT
// Internal: the frame every builder runs in — input checks, the deadline between steps, progress, and a
// check of the tree it returns — so that no builder repeats it and none can skip it.
#pragma once

#include <span>
#include <string_view>
#include <thread>

#include "hbvh/builders/context.hpp"
#include "hbvh/geometry/primitive.hpp"
#include "hbvh/result.hpp"
#include "hbvh/tree/bvh.hpp"

namespace hbvh::detail {

/// How a root over every primitive is fitted: by fit_best, or, once a deadline has passed, by the quick fitter
/// (fit_fast) above quick_root_min_primitives: fit_best over 10^5 primitives took 0.85 s, which a build stopped by its
/// time limit added to it, while below that it takes milliseconds and the quick root cost up to 60 % more than the
/// two-level tree's (16 generated primitives: +40 %).
enum class RootFit { best, quick };
inline constexpr std::size_t quick_root_min_primitives = std::size_t{1} << 14;
/// A volume around every primitive, fitted as `fit` says.
[[nodiscard]] BoundingVolume root_volume(std::span<const Primitive> primitives, const VolumePolicy& policy, RootFit fit);
/// The survey's two-level tree: one root (fit_best, or `fit`) over every primitive; no checks (two_level.cpp).
[[nodiscard]] Bvh two_level_tree(std::span<const Primitive> primitives, const VolumePolicy& policy,
                                 RootFit fit = RootFit::best);

/// Thrown by Checkpoint::step once the deadline has passed; caught by guarded_build only.
struct DeadlinePassed {};

/// A builder's "between steps": the deadline and the progress callback, out of `total` steps.
class Checkpoint {
public:
    Checkpoint(const BuildContext& context, double total)
        : context_(context), total_(total > 0.0 ? total : 1.0), caller_(std::this_thread::get_id()) {}

    /// Throws DeadlinePassed once the deadline has passed; reports done / total (on the calling thread
    /// only: the callback draws on a terminal, and parallel builders call this from worker threads too).
    void step(double done) const {
        if (context_.expired()) throw DeadlinePassed{};
        if (context_.progress && std::this_thread::get_id() == caller_) context_.progress(done / total_);
    }
    /// Reports done / total without looking at the deadline (for builders that handle it themselves).
    void report(double done) const {
        if (context_.progress && std::this_thread::get_id() == caller_) context_.progress(done / total_);
    }
    [[nodiscard]] const BuildContext& context() const { return context_; }

private:
    const BuildContext& context_;
    double total_;
    std::thread::id caller_;
};

/// Ok, or the Error that refuses the input: a policy validate_policy refuses, no primitives, invalid geometry
/// (validate_primitives), or a world box whose volume is not a finite normal double (check_finite_extent).
[[nodiscard]] Status check_build_input(std::span<const Primitive> primitives, const VolumePolicy& policy);
/// `built`, or an Error naming `builder` when the tree fails check_structure (a fitter that overflowed on
/// extreme input would otherwise write NaN volumes into a file).
[[nodiscard]] Result<Bvh> check_build_output(Result<Bvh> built, std::string_view builder);
/// The tree a builder returns when its deadline passed mid-way: one root over every primitive (the
/// survey's two-level tree), noted in the report with budget_hit.
[[nodiscard]] Bvh tree_at_deadline(std::span<const Primitive> primitives, const BuildContext& context,
                                   std::string_view builder);

/// Runs `body(checkpoint)` (returning Result<Bvh> or Bvh) between the input and output checks; if the
/// deadline passes at one of its checkpoints, returns tree_at_deadline instead.
template <class Body>
Result<Bvh> guarded_build(std::span<const Primitive> primitives, const BuildContext& context, std::string_view builder,
                          double steps, Body&& body) {
    if (Status input = check_build_input(primitives, context.policy); !input) return input.error();
    const Checkpoint checkpoint(context, steps);
    try {
        checkpoint.step(0.0);
        Result<Bvh> built = body(checkpoint);
        if (built) context.report_progress(1.0);
        return check_build_output(std::move(built), builder);
    } catch (const DeadlinePassed&) {
        return check_build_output(tree_at_deadline(primitives, context, builder), builder);
    }
}

}  // namespace hbvh::detail
