// SPDX-License-Identifier: MIT
#include "hbvh/build/two_level.hpp"

#include <numeric>

#include "hbvh/fit/fit.hpp"

namespace hbvh {

Bvh build_two_level(std::span<const Primitive> primitives, const VolumePolicy& policy) {
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
