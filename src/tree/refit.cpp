// SPDX-License-Identifier: MIT
#include "hbvh/tree/refit.hpp"

#include <vector>

#include "hbvh/fit/fit.hpp"

namespace hbvh {

std::size_t refit_non_enclosing(Bvh& bvh, double relative_tolerance) {
    const std::vector<ContainmentViolation> violations = containment_violations(bvh, relative_tolerance);
    for (const ContainmentViolation& violation : violations) {
        FitInput input;
        for (std::uint32_t p : covered_primitives(bvh, violation.node)) input.add(bvh.primitives[p].volume);
        Node& node = bvh.nodes[violation.node];
        node.volume = fit(type_of(node.volume), input.spheres, input.hint_axes);
    }
    return violations.size();
}

}  // namespace hbvh
