// SPDX-License-Identifier: MIT
// BuildContext: what every builder shares — the volume policy, the deadline, the progress callback and the
// report sink — passed as one argument so that every builder has the same shape (STYLE.md §3).
#pragma once

#include <chrono>
#include <functional>

#include "hbvh/builders/report.hpp"
#include "hbvh/fit/volume_policy.hpp"

namespace hbvh {

struct BuildContext {
    using Clock = std::chrono::steady_clock;

    /// Which BV kinds inner nodes may use, and their cost weights.
    VolumePolicy policy;
    /// When the build must be done. Every builder checks it between its steps and, once it has passed,
    /// finishes the tree the cheapest way it has (a flat group over what is left) and sets
    /// report->budget_hit. The default never passes.
    Clock::time_point deadline = Clock::time_point::max();
    /// Called with the fraction done, in [0, 1] and never decreasing (0 as a build starts, 1 when it is done),
    /// between steps, from the calling thread. Empty: no calls. The
    /// library never prints; the CLI draws the bar.
    std::function<void(double fraction)> progress;
    /// Filled when non-null: per-level rows, notes, lower bound, budget_hit.
    BuildReport* report = nullptr;

    /// A context whose deadline is `seconds` from now (0 or less, NaN, or beyond what the clock can hold, about
    /// 292 years: none).
    [[nodiscard]] BuildContext with_time_limit(double seconds) const {
        BuildContext limited = *this;
        const Clock::time_point now = Clock::now();
        // Converted only when it fits: a cast of more seconds than the clock's ticks hold overflows, and such a
        // deadline landed in the past (--time-limit 1e10 stopped every builder at once).
        const double seconds_left_on_clock = std::chrono::duration<double>(Clock::time_point::max() - now).count();
        limited.deadline = seconds > 0.0 && seconds < 0.5 * seconds_left_on_clock
                               ? now + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds))
                               : Clock::time_point::max();
        return limited;
    }
    [[nodiscard]] bool has_deadline() const { return deadline != Clock::time_point::max(); }
    /// True once the deadline has passed.
    [[nodiscard]] bool expired() const { return has_deadline() && Clock::now() >= deadline; }
    /// Seconds until the deadline (0 when passed, 0 too when there is none: check has_deadline()).
    [[nodiscard]] double seconds_left() const {
        if (!has_deadline()) return 0.0;
        const double left = std::chrono::duration<double>(deadline - Clock::now()).count();
        return left > 0.0 ? left : 0.0;
    }
    void report_progress(double fraction) const {
        if (progress) progress(fraction);
    }
    /// Records that the deadline cut the build short, with what the builder did instead.
    void note_deadline(const std::string& what) const {
        if (report == nullptr) return;
        report->budget_hit = true;
        if (report->time_limit.empty()) report->time_limit = what;
        report->notes.push_back(what);
    }
};

}  // namespace hbvh
