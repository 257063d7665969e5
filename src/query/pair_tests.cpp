// SPDX-License-Identifier: MIT
// The per-query pieces both queries share (query/pair_tests.hpp).
#include "pair_tests.hpp"

#include <string>

#include "hbvh/geometry/validation.hpp"

namespace hbvh::detail {

MovedLeaves& moved_leaves() {
    thread_local MovedLeaves leaves;
    return leaves;
}

void reset(CollideResult& result) {
    result.intersecting = false;
    result.error.reset();
    result.pairs.clear();
    result.bv_tests = result.primitive_tests = result.nodes_visited = 0;
}

bool poses_valid(const RigidTransform& pose_a, const RigidTransform& pose_b, CollideResult& result) {
    if (is_rigid_motion(pose_a) && is_rigid_motion(pose_b)) return true;  // the words only when needed
    for (const RigidTransform* pose : {&pose_a, &pose_b}) {
        if (std::string problem = pose_problem(*pose); !problem.empty()) {
            result.error = Error{(pose == &pose_a ? "pose_a: " : "pose_b: ") + problem};
            return false;
        }
    }
    return true;
}

}  // namespace hbvh::detail
