// SPDX-License-Identifier: MIT
// Mesh import (via assimp: glTF, OBJ, FBX, DAE, STL, PLY, ...): collision primitives from game assets.
#pragma once

#include <string>

#include "hbvh/fit/volume_policy.hpp"
#include "hbvh/io/import.hpp"

namespace hbvh {

/// How import_mesh turns meshes into primitives.
struct MeshImportOptions {
    /// For a plain mesh (no UBX_/USP_/UCP_/UCX_ pieces): fit one primitive per mesh node with fit_best.
    /// Ignored when the file has convention-named collision meshes.
    bool one_primitive_per_mesh = false;
    /// The kinds fit_best may pick for UCX_ pieces and for one_primitive_per_mesh.
    VolumePolicy policy = VolumePolicy::all();
};

/// Reads the mesh file at `path` and fits primitives to its vertices in world space (node transforms applied;
/// units are the file's own, assimp's unit scaling is not applied).
///
/// The game-engine collision naming convention (Unreal's): a mesh whose node name (or, failing that, mesh name)
/// starts with UBX_ becomes fit_obb of its vertices, USP_ fit_sphere, UCP_ fit_capsule, UCX_ (a convex piece)
/// fit_best under options.policy. When any such mesh exists the other (render) meshes are ignored, with one
/// warning. Otherwise options.one_primitive_per_mesh fits one primitive per mesh node. Names: the node's name
/// (the mesh's when the node has none), with "_<i>" added when a node holds several meshes.
///
/// Errors (file, and line when assimp names one): unreadable or unsupported file, no meshes, a vertex that is not
/// finite, or a plain mesh without one_primitive_per_mesh (nothing to import). Assimp never prints: no logger is
/// attached.
[[nodiscard]] Result<ImportResult> import_mesh(const std::string& path, const MeshImportOptions& options = {});

}  // namespace hbvh
