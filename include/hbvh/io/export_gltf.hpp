// SPDX-License-Identifier: MIT
// glTF 2.0 export: every level of a hierarchy as translucent meshes, for any 3D viewer or DCC tool.
#pragma once

#include <string>

#include "hbvh/io/bv_mesh.hpp"
#include "hbvh/result.hpp"
#include "hbvh/tree/bvh.hpp"

namespace hbvh {

/// Choices for export_gltf; the defaults give the survey's side-by-side picture.
struct GltfOptions {
    MeshDetail detail;          ///< Tessellation of spheres and capsules.
    bool side_by_side = true;   ///< Place level d at d x 1.25 x (root's world-AABB width) along +x.
    double opacity = 0.35;      ///< Alpha of the level materials (carried leaves: a little more).
};

/// A self-contained glTF 2.0 asset (JSON; the binary buffer is embedded as a base64 data URI).
///
/// The default scene has one node per level, named "level 0", "level 1", ..., each holding one child
/// node per BV shown on that level (see LevelView: the level's own nodes plus carried leaves). Children
/// are named "node I (type)" for inner nodes and "primitive P (type)" or "primitive P 'name' (type)"
/// for leaves, and carry {"hbvh_node", "volume", "carried"} in their extras; level nodes carry
/// {"depth", "nodes", "carried", "volume", "cost"}. Every BV is a triangle mesh with normals
/// (triangulate()); each level has its own translucent material (alphaMode BLEND, double-sided,
/// colour level_color(depth)) and carried leaves share a grey one. Each BV's node is placed at the centre of
/// the BV's world AABB by its "translation" (JSON doubles, so the placement is exact) and its mesh is stored
/// about that centre as 32-bit floats: a model 10^5 units from the origin keeps its millimetres, where world
/// coordinates as floats had kept 8 mm. An empty hierarchy gives a valid asset with an empty scene. Error for a
/// BV wider than a float can hold (3.4e38), whose mesh no viewer could draw.
[[nodiscard]] Result<std::string> export_gltf(const Bvh& bvh, const GltfOptions& options = {});

}  // namespace hbvh
