// SPDX-License-Identifier: MIT
// libFuzzer harness for the mesh importer on .obj input (assimp picks its reader by extension): any bytes give
// primitives or an Error, never a crash or a hang, and what is accepted is valid geometry. Both modes run: the
// UBX_/USP_/UCP_/UCX_ naming convention, and one primitive per mesh.
#include <cstddef>
#include <cstdint>

#include "check_import.hpp"
#include "hbvh/io/mesh_import.hpp"
#include "scratch_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string path = hbvh::fuzz::write_scratch_file("mesh.obj", data, size);
    hbvh::fuzz::check_imported(hbvh::import_mesh(path));
    hbvh::MeshImportOptions per_mesh;
    per_mesh.one_primitive_per_mesh = true;
    hbvh::fuzz::check_imported(hbvh::import_mesh(path, per_mesh));
    return 0;
}
