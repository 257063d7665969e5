// SPDX-License-Identifier: MIT
// Mesh import: assimp reads the file, the fitters turn each collision mesh's world-space vertices into a BV.
#include "hbvh/io/mesh_import.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <regex>
#include <type_traits>
#include <variant>

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include "hbvh/fit/fit.hpp"
#include "ply_header.hpp"

namespace hbvh {
namespace {

// The collision kinds of the naming convention, by prefix.
enum class CollisionKind { none, box, sphere, capsule, convex };

CollisionKind kind_of(std::string_view name) {
    if (name.starts_with("UBX_")) return CollisionKind::box;
    if (name.starts_with("USP_")) return CollisionKind::sphere;
    if (name.starts_with("UCP_")) return CollisionKind::capsule;
    if (name.starts_with("UCX_")) return CollisionKind::convex;
    return CollisionKind::none;
}

// One mesh instance in the scene: its vertices in world space and the name that decides its role.
struct MeshInstance {
    std::string name;
    CollisionKind kind = CollisionKind::none;
    std::vector<Sphere> points;  // Vertices as radius-0 spheres, the fitters' input.
    double rounding = 0.0;       // How far a vertex may lie from the file's own (single_precision_reach).
};

/// How far a vertex that assimp read and placed may lie from where the file puts it, for a vertex whose coordinates
/// are at most `magnitude` in size (the largest |M v| + |t| row sum of its transform): assimp reads and transforms
/// in single precision (Debian builds it without ASSIMP_DOUBLE_PRECISION). Parsing text is within an ulp, and each
/// coordinate's three products and sums round at most 2.5 ulps of that magnitude more: 4 ulps per coordinate,
/// times sqrt(3) for the distance. At 10^6 (an ulp of 0.0625) that is 0.43; at 1, 8e-7.
double single_precision_reach(double magnitude) {
    static_assert(std::is_same_v<ai_real, float>, "with a double-precision assimp this margin is far too large");
    if (!(magnitude > 0.0)) return 0.0;
    const double ulp = std::ldexp(1.0, std::max(std::ilogb(magnitude), -126) - 23);  // of a float as large
    return std::sqrt(3.0) * 4.0 * ulp;
}

/// `volume` grown by `margin` in every direction: boxes by their half extents, spheres and capsules by the radius.
void grow(BoundingVolume& volume, double margin) {
    if (auto* sphere = std::get_if<Sphere>(&volume)) sphere->radius += margin;
    else if (auto* capsule = std::get_if<Capsule>(&volume)) capsule->radius += margin;
    else if (auto* box = std::get_if<Obb>(&volume)) box->half_extents.array() += margin;
    else if (auto* aabb = std::get_if<Aabb>(&volume)) aabb->min.array() -= margin, aabb->max.array() += margin;
}

// assimp reports parse errors as text; some of them carry "line N".
int line_in(const std::string& message) {
    static const std::regex line_pattern(R"(line[ :]+(\d+))", std::regex::icase);
    std::smatch match;
    if (!std::regex_search(message, match, line_pattern)) return 0;
    // Messages can quote the file's own text, so the digits may not fit an int (std::stoi would throw).
    int line = 0;
    const std::string digits = match[1].str();
    const auto [end, code] = std::from_chars(digits.data(), digits.data() + digits.size(), line);
    return code == std::errc() && end == digits.data() + digits.size() ? line : 0;
}

Status collect_instances(const aiScene& scene, const aiNode& node, const aiMatrix4x4& parent_transform,
                         const std::string& path, std::vector<MeshInstance>& out) {
    const aiMatrix4x4 transform = parent_transform * node.mTransformation;
    for (unsigned i = 0; i < node.mNumMeshes; ++i) {
        const aiMesh& mesh = *scene.mMeshes[node.mMeshes[i]];
        // The node carries the artist's object name in most exporters; fall back to the mesh name.
        std::string name = node.mName.length > 0 ? node.mName.C_Str() : mesh.mName.C_Str();
        CollisionKind kind = kind_of(name);
        if (kind == CollisionKind::none && kind_of(mesh.mName.C_Str()) != CollisionKind::none) {
            name = mesh.mName.C_Str();
            kind = kind_of(name);
        }
        if (node.mNumMeshes > 1) name += "_" + std::to_string(i);
        MeshInstance instance{name, kind, {}};
        instance.points.reserve(mesh.mNumVertices);
        double magnitude = 0.0;
        for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
            const aiVector3D& local = mesh.mVertices[v];
            const aiVector3D world = transform * local;
            const Vec3 point(world.x, world.y, world.z);
            if (!point.allFinite())
                return Error("mesh '" + name + "' has a vertex that is not finite (meshes are read in single precision, "
                             "whose range ends at 3.4e38)",
                             path);
            instance.points.push_back({point, 0.0});
            for (unsigned row = 0; row < 3; ++row)
                magnitude = std::max(magnitude, std::abs(double(transform[row][0]) * local.x) +
                                                    std::abs(double(transform[row][1]) * local.y) +
                                                    std::abs(double(transform[row][2]) * local.z) +
                                                    std::abs(double(transform[row][3])));
        }
        instance.rounding = single_precision_reach(magnitude);
        out.push_back(std::move(instance));
    }
    for (unsigned c = 0; c < node.mNumChildren; ++c)
        if (Status status = collect_instances(scene, *node.mChildren[c], transform, path, out); !status) return status;
    return Ok{};
}

// Whether a fitted volume is a single point (every vertex of the mesh at one place): nothing to collide with, so
// skipped with a warning, as URDF's points are. A flat mesh (a floor, a wall, a sign) fits a box of zero thickness
// and a line of vertices a capsule of radius zero: valid primitives that the survey format keeps (zero sizes are
// allowed), which until 2026-12-08 were skipped as well, although a UBX_ floor that rounding left a tiny thickness
// was kept.
bool is_a_point(const BoundingVolume& volume) {
    const Aabb box = world_aabb(volume);
    return box.min == box.max;
}

}  // namespace

Result<ImportResult> import_mesh(const std::string& path, const MeshImportOptions& options) {
    // Only positions are needed: no normals, no triangulation. Assimp has no logger unless one is created, so it
    // stays silent.
    if (Status header = detail::check_ply_header(path); !header) return header.error();
    Assimp::Importer importer;
    const aiScene* scene = importer.ReadFile(path, aiProcess_ValidateDataStructure);
    if (scene == nullptr || scene->mRootNode == nullptr) {
        const std::string reason = importer.GetErrorString();
        return Error("cannot read mesh: " + (reason.empty() ? std::string("unknown assimp error") : reason), path,
                     line_in(reason));
    }
    std::vector<MeshInstance> instances;
    if (Status status = collect_instances(*scene, *scene->mRootNode, aiMatrix4x4(), path, instances); !status)
        return status.error();
    if (instances.empty()) return Error("the file holds no meshes", path);

    ImportResult result;
    const bool has_collision_meshes = std::any_of(instances.begin(), instances.end(), [](const MeshInstance& m) {
        return m.kind != CollisionKind::none;
    });
    if (!has_collision_meshes && !options.one_primitive_per_mesh)
        return Error("no collision meshes (names starting UBX_, USP_, UCP_ or UCX_); set one_primitive_per_mesh "
                     "(the CLI's --format mesh-nodes, --input-format in hbvh export) to fit one primitive per render mesh",
                     path);
    std::size_t ignored = 0;
    for (const MeshInstance& instance : instances) {
        if (has_collision_meshes && instance.kind == CollisionKind::none) {
            ++ignored;
            continue;
        }
        if (instance.points.empty()) {
            result.warnings.push_back(Error("mesh '" + instance.name + "' has no vertices; skipped", path).to_string());
            continue;
        }
        BoundingVolume volume;
        switch (instance.kind) {
            case CollisionKind::box: volume = fit_obb(instance.points); break;
            case CollisionKind::sphere: volume = fit_sphere(instance.points); break;
            case CollisionKind::capsule: volume = fit_capsule(instance.points); break;
            case CollisionKind::convex:
            case CollisionKind::none: volume = fit_best(instance.points, options.policy); break;
        }
        if (is_a_point(volume)) {
            result.warnings.push_back(
                Error("mesh '" + instance.name + "' is a single point (all its vertices coincide); skipped", path)
                    .to_string());
            continue;
        }
        // The fit encloses the vertices as assimp gave them; grown by their rounding, the file's own vertices too.
        grow(volume, instance.rounding);
        result.primitives.push_back({std::move(volume), instance.name});
    }
    if (ignored > 0)
        result.warnings.push_back(Error(std::to_string(ignored) +
                                            " render mesh(es) ignored: the file has UBX_/USP_/UCP_/UCX_ collision meshes",
                                        path)
                                      .to_string());
    return result;
}

}  // namespace hbvh
