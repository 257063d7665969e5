// SPDX-License-Identifier: MIT
#include "guarded_build.hpp"

#include <string>

#include "hbvh/builders/build.hpp"
#include "hbvh/geometry/validation.hpp"
#include "hbvh/tree/validate.hpp"

namespace hbvh::detail {

Status check_build_input(std::span<const Primitive> primitives, const VolumePolicy& policy) {
    if (Status usable = validate_policy(policy); !usable) return usable;
    if (primitives.empty()) return Error{"no primitives to build a hierarchy over"};
    if (Status valid = validate_primitives(primitives); !valid) return valid;
    return check_finite_extent(primitives);
}

Result<Bvh> check_build_output(Result<Bvh> built, std::string_view builder) {
    if (!built) return built;
    if (Status structure = check_structure(*built); !structure)
        return Error{std::string(builder) + " produced an unusable tree (" + structure.error().message +
                     "); the input's scale is probably beyond what double precision can fit"};
    return built;
}

Bvh tree_at_deadline(std::span<const Primitive> primitives, const BuildContext& context, std::string_view builder) {
    context.note_deadline(std::string(builder) + ": time limit reached before the tree was done; returned the "
                          "two-level tree (one root over every primitive)");
    return two_level_tree(primitives, context.policy, RootFit::quick);
}

}  // namespace hbvh::detail
