// SPDX-License-Identifier: MIT
// Primitive: one of the artist's volumes, the leaves of every hierarchy.
#pragma once

#include <string>

#include "hbvh/geometry/bounding_volume.hpp"

namespace hbvh {

/// An input volume. Its BV is the leaf's BV; `name` is optional and carried through to output.
struct Primitive {
    BoundingVolume volume;
    std::string name;
};

}  // namespace hbvh
