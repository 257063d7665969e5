// SPDX-License-Identifier: MIT
#include "hbvh/builders/two_level.hpp"

#include <numeric>

#include "guarded_build.hpp"
#include "hbvh/fit/fit.hpp"

namespace hbvh {

Result<Bvh> build_two_level(std::span<const Primitive> primitives, const BuildContext& context,
                            const TwoLevelOptions& /*options*/) {
    return detail::guarded_build(primitives, context, "two-level", 1.0,
                                 [&](const detail::Checkpoint&) { return detail::two_level_tree(primitives, context.policy); });
}

Bvh detail::two_level_tree(std::span<const Primitive> primitives, const VolumePolicy& policy) {
    TreeAssembler assembler(primitives);
    std::vector<std::uint32_t> leaves(primitives.size());
    FitInput input;
    for (std::uint32_t i = 0; i < primitives.size(); ++i) {
        leaves[i] = assembler.add_leaf(i);
        input.add(primitives[i].volume);
    }
    if (leaves.size() == 1) return std::move(assembler).finish(leaves.front());
    const std::uint32_t root = assembler.add_group(leaves, fit_best(input.spheres, policy, input.hint_axes));
    return std::move(assembler).finish(root);
}

}  // namespace hbvh
