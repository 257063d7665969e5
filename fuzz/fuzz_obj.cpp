// SPDX-License-Identifier: MIT
// libFuzzer harness for the mesh importer on .obj input (assimp picks its reader by extension): any bytes give
// primitives or an Error, never a crash or a hang, and what is accepted is valid geometry. One call per input, with
// one_primitive_per_mesh: it covers both modes (the UBX_/USP_/UCP_/UCX_ convention wins whenever such names
// exist, and plain meshes are fitted instead of refused), and assimp's parse dominates the time of a run.
#include <cstddef>
#include <cstdint>

#include "check_import.hpp"
#include "hbvh/io/mesh_import.hpp"
#include "scratch_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string path = hbvh::fuzz::write_scratch_file("mesh.obj", data, size);
    hbvh::MeshImportOptions options;
    options.one_primitive_per_mesh = true;
    hbvh::fuzz::check_imported(hbvh::import_mesh(path, options));
    return 0;
}
