// SPDX-License-Identifier: MIT
// import_primitives: one entry point that picks the importer from the file name (and, for .xml, the root).
#include "hbvh/io/import.hpp"

#include <algorithm>
#include <array>

#include "hbvh/io/file.hpp"
#include "hbvh/io/mesh_import.hpp"
#include "hbvh/io/mjcf.hpp"
#include "hbvh/io/urdf.hpp"
#include "hbvh/io/xml.hpp"
#include "import_format.hpp"
#include "xml_source.hpp"

namespace hbvh {
namespace {

Result<ImportFormat> format_from_path(const std::string& path) {
    const std::string extension = lower_case_extension(path);
    if (extension == ".urdf") return ImportFormat::urdf;
    if (detail::is_mesh_extension(extension)) return ImportFormat::mesh;
    if (extension == ".xml") {
        // MJCF, URDF saved as .xml, and the survey format share the extension: the root element decides.
        Result<std::unique_ptr<detail::XmlSource>> source = detail::XmlSource::load(path);
        if (!source) return source.error();
        const std::string_view root = (*source)->document().document_element().name();
        if (root == "mujoco") return ImportFormat::mjcf;
        if (root == "robot") return ImportFormat::urdf;
        return ImportFormat::survey_xml;
    }
    return Error("unknown file type '" + extension + "' (expected .xml, .urdf, .gltf, .glb, .obj, .fbx, .dae, .stl "
                 "or .ply)",
                 path);
}

}  // namespace

namespace detail {

bool is_mesh_extension(std::string_view extension) {
    static constexpr std::array<std::string_view, 7> mesh_extensions{".gltf", ".glb", ".obj", ".fbx",
                                                                     ".dae",  ".stl", ".ply"};
    return std::find(mesh_extensions.begin(), mesh_extensions.end(), extension) != mesh_extensions.end();
}

bool is_import_extension(std::string_view extension) {
    return extension == ".xml" || extension == ".urdf" || is_mesh_extension(extension);
}

}  // namespace detail

Result<ImportResult> import_primitives(const std::string& path, ImportFormat format) {
    if (format == ImportFormat::automatic) {
        Result<ImportFormat> detected = format_from_path(path);
        if (!detected) return detected.error();
        format = *detected;
    }
    switch (format) {
        case ImportFormat::mjcf: return import_mjcf(path);
        case ImportFormat::urdf: return import_urdf(path);
        case ImportFormat::mesh: return import_mesh(path);
        case ImportFormat::survey_xml: {
            Result<XmlModel> model = read_xml_file(path);
            if (!model) return model.error();
            ImportResult result{std::move(model->primitives), {}};
            // Importing means "primitives in": a stored hierarchy is not an input to the builders.
            if (model->hierarchy)
                result.warnings.push_back(
                    Error("the file's hierarchy is ignored; its leaf volumes are imported as primitives", path).to_string());
            return result;
        }
        case ImportFormat::automatic: break;
    }
    return Error("no importer for the requested format", path);
}

}  // namespace hbvh
