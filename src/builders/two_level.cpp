// SPDX-License-Identifier: MIT
#include "hbvh/builders/two_level.hpp"

#include <numeric>

#include "guarded_build.hpp"
#include "hbvh/fit/fit.hpp"
#include "hbvh/fit/fit_fast.hpp"

namespace hbvh {

Result<Bvh> build_two_level(std::span<const Primitive> primitives, const BuildContext& context,
                            const TwoLevelOptions& /*options*/) {
    return detail::guarded_build(primitives, context, "two-level", 1.0,
                                 [&](const detail::Checkpoint&) { return detail::two_level_tree(primitives, context.policy); });
}

BoundingVolume detail::root_volume(std::span<const Primitive> primitives, const VolumePolicy& policy, RootFit fit) {
    FitInput input;
    for (const Primitive& primitive : primitives) input.add(primitive.volume);
    if (fit == RootFit::quick && primitives.size() > quick_root_min_primitives)
        return fit_fast(input.spheres, {}, policy, FastFitMode::quick_sphere);
    return fit_best(input.spheres, policy, input.hint_axes);
}

Bvh detail::two_level_tree(std::span<const Primitive> primitives, const VolumePolicy& policy, RootFit fit) {
    TreeAssembler assembler(primitives);
    std::vector<std::uint32_t> leaves(primitives.size());
    for (std::uint32_t i = 0; i < primitives.size(); ++i) leaves[i] = assembler.add_leaf(i);
    if (leaves.size() == 1) return std::move(assembler).finish(leaves.front());
    const std::uint32_t root = assembler.add_group(leaves, root_volume(primitives, policy, fit));
    return std::move(assembler).finish(root);
}

}  // namespace hbvh
