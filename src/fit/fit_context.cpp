// SPDX-License-Identifier: MIT
// The per-call work the OBB and capsule fitters share, computed once.
#include "fit_context.hpp"

#include "hbvh/assert.hpp"

namespace hbvh::detail {

FitContext make_fit_context(std::span<const Sphere> spheres, std::span<const Mat3> hint_axes) {
    HBVH_ASSERT(!spheres.empty());
    FitContext context;
    context.hull = summarize_hull(spheres);
    context.proxy = make_proxy(spheres, context.hull);
    context.dito = dito_frames(spheres);
    context.hints = select_hints(context.proxy, hint_axes);
    return context;
}

}  // namespace hbvh::detail
