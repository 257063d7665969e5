// SPDX-License-Identifier: MIT
// Which file names the importers recognise, shared by import_primitives and read_model_file (which reads a file
// of any other name by its content).
#pragma once

#include <string_view>

namespace hbvh::detail {

/// True for the extensions import_primitives decides by (.xml, .urdf and the mesh formats), lower case with the dot.
[[nodiscard]] bool is_import_extension(std::string_view extension);

/// True for the extensions of the mesh formats assimp reads for hbvh (.gltf .glb .obj .fbx .dae .stl .ply).
[[nodiscard]] bool is_mesh_extension(std::string_view extension);

}  // namespace hbvh::detail
