// SPDX-License-Identifier: MIT
// MJCF (MuJoCo XML) import: the collision geoms of a model as hbvh primitives, read straight from the XML.
#pragma once

#include <string>

#include "hbvh/io/import.hpp"

namespace hbvh {

/// Reads the collision geoms of the MJCF model at `path`, placed in world space at the pose the XML describes
/// (joints at their reference value, keyframes ignored). Units are the file's (metres in practice).
///
/// Rules (full list in docs/importers.md): default classes with nesting, `class` and inherited `childclass`;
/// body frames composed down the tree; pos, quat (w first, normalised), euler (<compiler eulerseq>), axisangle,
/// xyaxes, zaxis, <compiler angle> (degree by default); fromto on capsule, cylinder, box and ellipsoid; sizes
/// are half sizes; <include file> (relative to the main file's folder) and <frame> are followed. A geom is
/// collision geometry when contype or conaffinity is non-zero after defaults. box -> Obb, sphere -> Sphere,
/// capsule -> Capsule, cylinder -> enclose_cylinder, ellipsoid -> enclose_ellipsoid (io/solid_shapes.hpp).
/// Skipped: plane and hfield geoms and sites (not primitives, no warning); mesh and sdf geoms, primitives fitted
/// to a mesh, <composite>, <flexcomp>, <replicate>, <attach> (each with a warning).
/// Names: the geom's name, else "<body name>_geom<i>" with i the geom's index in its body ("world" for
/// <worldbody>, "body<id>" for an unnamed body, id in depth-first order as in MuJoCo).
///
/// Errors (file, line, problem): unreadable or malformed XML, root not <mujoco>, unknown default class, bad or
/// missing numbers, several orientations on one element, non-positive sizes, degenerate fromto/axes,
/// <compiler coordinate="global">, include cycles. No MuJoCo library is needed or used.
[[nodiscard]] Result<ImportResult> import_mjcf(const std::string& path);

}  // namespace hbvh
