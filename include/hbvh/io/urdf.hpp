// SPDX-License-Identifier: MIT
// URDF import (via urdfdom): every <collision> of every link as an hbvh primitive.
#pragma once

#include <string>

#include "hbvh/io/import.hpp"

namespace hbvh {

/// Reads the collision geometry of the URDF robot at `path`, in world space (the root link's frame) with every
/// joint at q = 0. Units are the file's (metres).
///
/// Rules (docs/importers.md): link frames compose joint <origin>s from the root link outward; <origin rpy> is
/// about fixed axes, R = Rz(yaw) Ry(pitch) Rx(roll); missing origin parts are zero. box (full sizes) -> Obb,
/// sphere -> Sphere, cylinder (full length) -> enclose_cylinder, capsule (Bullet/Drake extension; `length` is the
/// cylinder part) -> Capsule. Primitives come in document order of links, then of collisions within a link.
/// Skipped with a warning: mesh collisions (package:// URIs cannot be resolved) and zero-size placeholder shapes
/// (Drake puts radius-0 spheres on frame-only links). Names: the collision's name, else "<link>_collision<i>".
///
/// Errors (file, line when known, problem): unreadable or malformed XML, root not <robot>, bad capsule numbers,
/// negative sizes, and anything urdfdom rejects (its messages are captured, never printed).
/// Not thread-safe with other users of console_bridge, whose log handler is swapped during parsing.
[[nodiscard]] Result<ImportResult> import_urdf(const std::string& path);

}  // namespace hbvh
