// SPDX-License-Identifier: MIT
// The objects the query benchmarks measure on: the bundled models, the robots of ../shared/data when that
// folder is beside the checkout, and seeded generated objects, in one fixed order.
#pragma once

#include <string>
#include <vector>

#include "hbvh/geometry/primitive.hpp"

namespace hbvh::bench {

struct BenchObject {
    std::string name;
    std::vector<Primitive> primitives;
};

/// data/models/*.xml (sorted), ../shared/data/models/*.{xml,urdf} (sorted; skipped with a note on stderr when
/// unreadable or under 2 primitives) and `generate_scene` objects of 13, 27, 100 and 1000 primitives (seed 2024).
/// `program` names the caller in the notes.
[[nodiscard]] std::vector<BenchObject> load_bench_objects(const std::string& program);

}  // namespace hbvh::bench
