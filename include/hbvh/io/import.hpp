// SPDX-License-Identifier: MIT
// Importing collision primitives from robot descriptions (MJCF, URDF) and game assets (meshes).
#pragma once

#include <string>
#include <vector>

#include "hbvh/geometry/primitive.hpp"
#include "hbvh/result.hpp"

namespace hbvh {

/// What an importer read: the primitives in world space (metres for MJCF and URDF, the file's own units for
/// meshes) and notes about input it skipped on purpose (mesh geoms, unsupported generators, ...).
struct ImportResult {
    std::vector<Primitive> primitives;
    std::vector<std::string> warnings;  ///< One line each, "file:line: what was skipped and why" when known.
};

/// Input formats import_primitives understands.
enum class ImportFormat {
    automatic,  ///< Decide by extension (and, for .xml, by the root element).
    mjcf,       ///< MuJoCo XML (root <mujoco>).
    urdf,       ///< ROS URDF (root <robot>).
    mesh,       ///< Anything assimp reads: glTF, OBJ, FBX, DAE, STL, PLY, ...
    survey_xml  ///< hbvh's own primitive XML (io/xml.hpp); a stored hierarchy is dropped with a warning.
};

/// Reads primitives from `path` in `format`. With ImportFormat::automatic: .urdf -> URDF; .xml -> MJCF when the
/// root element is <mujoco>, else the survey format; .gltf .glb .obj .fbx .dae .stl .ply -> mesh (with default
/// MeshImportOptions). Errors: unreadable file, unknown extension, or the chosen importer's error.
[[nodiscard]] Result<ImportResult> import_primitives(const std::string& path,
                                                     ImportFormat format = ImportFormat::automatic);

}  // namespace hbvh
