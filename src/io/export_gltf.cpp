// SPDX-License-Identifier: MIT
// glTF 2.0 writer: one interleaved vertex buffer view, one index view, accessors per hierarchy node,
// meshes per (node, material). Layout per the glTF 2.0 specification, sections 3.6-3.9.
#include "hbvh/io/export_gltf.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>

#include "hbvh/io/level_view.hpp"
#include "hbvh/version.hpp"

namespace hbvh {
namespace {

using nlohmann::json;

// glTF enumerations (specification 5.1.1, 5.11.1).
constexpr int component_float = 5126;
constexpr int component_unsigned_int = 5125;
constexpr int target_array_buffer = 34962;
constexpr int target_element_array_buffer = 34963;
constexpr int mode_triangles = 4;
constexpr std::size_t vertex_stride = 24;  // position then normal, 3 floats each

/// RFC 4648 base64 with padding, as data URIs require.
std::string base64(const std::vector<std::uint8_t>& bytes) {
    static constexpr char alphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    out.reserve((bytes.size() + 2) / 3 * 4);
    for (std::size_t i = 0; i < bytes.size(); i += 3) {
        const std::size_t n = std::min<std::size_t>(3, bytes.size() - i);
        std::uint32_t chunk = std::uint32_t{bytes[i]} << 16;
        if (n > 1) chunk |= std::uint32_t{bytes[i + 1]} << 8;
        if (n > 2) chunk |= bytes[i + 2];
        for (std::size_t k = 0; k < 4; ++k)
            out += k <= n ? alphabet[(chunk >> (18 - 6 * k)) & 63u] : '=';
    }
    return out;
}

/// Little-endian writer: glTF buffers are little-endian whatever the host is.
class ByteWriter {
public:
    void put_u32(std::uint32_t value) {
        for (int shift = 0; shift < 32; shift += 8) bytes_.push_back(static_cast<std::uint8_t>(value >> shift));
    }
    void put_float(float value) { put_u32(std::bit_cast<std::uint32_t>(value)); }
    [[nodiscard]] std::size_t size() const { return bytes_.size(); }
    [[nodiscard]] const std::vector<std::uint8_t>& bytes() const { return bytes_; }

private:
    std::vector<std::uint8_t> bytes_;
};

json color_factor(const Rgb& color, double alpha) { return json::array({color[0], color[1], color[2], alpha}); }

json material(const std::string& name, const Rgb& color, double alpha) {
    return {{"name", name},
            {"pbrMetallicRoughness",
             {{"baseColorFactor", color_factor(color, alpha)}, {"metallicFactor", 0.0}, {"roughnessFactor", 0.8}}},
            {"alphaMode", "BLEND"},
            // Translucent volumes are seen from inside and through each other: draw back faces too.
            {"doubleSided", true}};
}

std::string node_name(const Bvh& bvh, std::uint32_t index) {
    const Node& node = bvh.nodes[index];
    const std::string type(to_string(type_of(node.volume)));
    if (!node.is_leaf()) return "node " + std::to_string(index) + " (" + type + ")";
    const Primitive& primitive = bvh.primitives[node.primitive];
    std::string name = "primitive " + std::to_string(node.primitive);
    if (!primitive.name.empty()) name += " '" + primitive.name + "'";
    return name + " (" + type + ")";
}

/// Accessors of one hierarchy node's mesh.
struct MeshAccessors {
    std::size_t position = 0;
    std::size_t normal = 0;
    std::size_t indices = 0;
};

}  // namespace

Result<std::string> export_gltf(const Bvh& bvh, const GltfOptions& options) {
    json gltf;
    gltf["asset"] = {{"version", "2.0"}, {"generator", std::string("hbvh ") + HBVH_VERSION_STRING}};
    gltf["scene"] = 0;
    json scene = {{"name", "hbvh levels"}};
    if (bvh.empty()) {
        gltf["scenes"] = json::array({scene});
        return gltf.dump(1, ' ', false, json::error_handler_t::replace);
    }

    // Stage 1: tessellate every node about its origin (the centre of its world AABB, which its glTF node's
    // translation restores); positions and normals interleaved in one buffer view, indices in a second.
    // Accessor min/max are taken from the float values actually stored, as validators demand.
    std::vector<TriangleMesh> meshes;
    std::vector<Vec3> origins;
    meshes.reserve(bvh.nodes.size());
    origins.reserve(bvh.nodes.size());
    for (const Node& node : bvh.nodes) {
        meshes.push_back(triangulate(node.volume, options.detail));
        origins.push_back(world_aabb(node.volume).center());
    }
    ByteWriter vertices, indices;
    json accessors = json::array();
    std::vector<MeshAccessors> node_accessors;
    node_accessors.reserve(meshes.size());
    for (std::size_t n = 0; n < meshes.size(); ++n) {
        const TriangleMesh& mesh = meshes[n];
        const std::size_t vertex_offset = vertices.size();
        const std::size_t index_offset = indices.size();
        std::array<float, 3> lo{}, hi{};
        lo.fill(std::numeric_limits<float>::infinity());
        hi.fill(-std::numeric_limits<float>::infinity());
        for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
            for (Eigen::Index k = 0; k < 3; ++k) {
                const auto value = static_cast<float>(mesh.positions[i][k] - origins[n][k]);
                if (!std::isfinite(value))
                    return Error{"node " + std::to_string(n) + " is wider than a glTF float holds (3.4e38)"};
                lo[k] = std::min(lo[k], value);
                hi[k] = std::max(hi[k], value);
                vertices.put_float(value);
            }
            const Vec3 normal = mesh.normals[i].normalized();
            for (Eigen::Index k = 0; k < 3; ++k) vertices.put_float(static_cast<float>(normal[k]));
        }
        for (std::uint32_t index : mesh.indices) indices.put_u32(index);
        const json count = mesh.positions.size();
        MeshAccessors ids;
        ids.position = accessors.size();
        accessors.push_back({{"bufferView", 0}, {"byteOffset", vertex_offset}, {"componentType", component_float},
                             {"count", count}, {"type", "VEC3"},
                             {"min", {lo[0], lo[1], lo[2]}}, {"max", {hi[0], hi[1], hi[2]}}});
        ids.normal = accessors.size();
        accessors.push_back({{"bufferView", 0}, {"byteOffset", vertex_offset + 12}, {"componentType", component_float},
                             {"count", count}, {"type", "VEC3"}});
        ids.indices = accessors.size();
        accessors.push_back({{"bufferView", 1}, {"byteOffset", index_offset},
                             {"componentType", component_unsigned_int}, {"count", mesh.indices.size()},
                             {"type", "SCALAR"}});
        node_accessors.push_back(ids);
    }
    std::vector<std::uint8_t> buffer = vertices.bytes();
    buffer.insert(buffer.end(), indices.bytes().begin(), indices.bytes().end());
    gltf["buffers"] = json::array(
        {{{"byteLength", buffer.size()}, {"uri", "data:application/octet-stream;base64," + base64(buffer)}}});
    gltf["bufferViews"] = json::array(
        {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", vertices.size()}, {"byteStride", vertex_stride},
          {"target", target_array_buffer}},
         {{"buffer", 0}, {"byteOffset", vertices.size()}, {"byteLength", indices.size()},
          {"target", target_element_array_buffer}}});
    gltf["accessors"] = std::move(accessors);

    // Stage 2: materials and meshes, created on first use so that nothing in the file is unused.
    const std::vector<LevelView> views = level_views(bvh);
    json materials = json::array();
    json mesh_list = json::array();
    std::optional<std::size_t> carried_material;
    std::vector<std::optional<std::size_t>> carried_mesh(bvh.nodes.size());
    const auto add_mesh = [&](std::uint32_t index, std::size_t material_index, const std::string& suffix) {
        const MeshAccessors& ids = node_accessors[index];
        mesh_list.push_back({{"name", node_name(bvh, index) + suffix},
                             {"primitives", json::array({{{"attributes", {{"POSITION", ids.position},
                                                                          {"NORMAL", ids.normal}}},
                                                         {"indices", ids.indices},
                                                         {"material", material_index},
                                                         {"mode", mode_triangles}}})}});
        return mesh_list.size() - 1;
    };

    // Stage 3: one glTF node per level with one child per BV it shows.
    const Aabb root_box = world_aabb(bvh.root().volume);
    const Vec3 size = root_box.max - root_box.min;
    double spacing = 1.25 * size.x();
    if (!(spacing > 0.0)) spacing = 1.25 * std::max(size.maxCoeff(), 1.0);
    json nodes = json::array();
    json level_nodes = json::array();
    for (const LevelView& view : views) {
        const std::size_t level_material = materials.size();
        materials.push_back(material("level " + std::to_string(view.depth), level_color(view.depth), options.opacity));
        json children = json::array();
        const auto at_origin = [&](std::uint32_t index) {
            const Vec3& o = origins[index];
            return json::array({o.x(), o.y(), o.z()});
        };
        for (std::uint32_t index : view.nodes) {
            nodes.push_back({{"name", node_name(bvh, index)},
                             {"mesh", add_mesh(index, level_material, "")},
                             {"translation", at_origin(index)},
                             {"extras", {{"hbvh_node", index}, {"volume", volume(bvh.nodes[index].volume)},
                                         {"carried", false}}}});
            children.push_back(nodes.size() - 1);
        }
        for (std::uint32_t index : view.carried) {
            if (!carried_material) {
                carried_material = materials.size();
                materials.push_back(material("carried leaves", carried_color(), std::min(1.0, options.opacity + 0.15)));
            }
            if (!carried_mesh[index]) carried_mesh[index] = add_mesh(index, *carried_material, " carried");
            nodes.push_back({{"name", node_name(bvh, index) + " carried"},
                             {"mesh", *carried_mesh[index]},
                             {"translation", at_origin(index)},
                             {"extras", {{"hbvh_node", index}, {"volume", volume(bvh.nodes[index].volume)},
                                         {"carried", true}}}});
            children.push_back(nodes.size() - 1);
        }
        json level = {{"name", "level " + std::to_string(view.depth)},
                      {"children", std::move(children)},
                      {"extras", {{"depth", view.depth}, {"nodes", view.nodes.size()}, {"carried", view.carried.size()},
                                  {"volume", view.volume}, {"cost", view.cost}}}};
        if (options.side_by_side && view.depth > 0)
            level["translation"] = {spacing * view.depth, 0.0, 0.0};
        nodes.push_back(std::move(level));
        level_nodes.push_back(nodes.size() - 1);
    }
    scene["nodes"] = std::move(level_nodes);
    gltf["scenes"] = json::array({std::move(scene)});
    gltf["nodes"] = std::move(nodes);
    gltf["meshes"] = std::move(mesh_list);
    gltf["materials"] = std::move(materials);
    return gltf.dump(1, ' ', false, json::error_handler_t::replace);
}

}  // namespace hbvh
