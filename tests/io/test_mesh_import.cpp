// SPDX-License-Identifier: MIT
// Mesh importer tests: the UBX_/USP_/UCP_/UCX_ convention in OBJ and glTF, node transforms, plain meshes.
#include "hbvh/io/mesh_import.hpp"

#include <chrono>
#include <fstream>

#include <unistd.h>

#include <gtest/gtest.h>

#include "io/import_test_support.hpp"

namespace hbvh {
namespace {

namespace fs = std::filesystem;

const Primitive* find(const ImportResult& result, const std::string& name) {
    for (const Primitive& p : result.primitives)
        if (p.name == name) return &p;
    return nullptr;
}

TEST(MeshImport, ObjCollisionConvention) {
    const Result<ImportResult> imported = import_mesh((test::test_data_dir() / "mesh_collision_convention.obj").string());
    ASSERT_TRUE(imported.has_value()) << imported.error().to_string();
    ASSERT_EQ(imported->primitives.size(), 4u);
    ASSERT_EQ(imported->warnings.size(), 1u);  // The render mesh is ignored, and the importer says so.
    EXPECT_NE(imported->warnings[0].find("1 render mesh"), std::string::npos);

    const Primitive* slab = find(*imported, "UBX_slab");
    ASSERT_NE(slab, nullptr);
    ASSERT_TRUE(std::holds_alternative<Obb>(slab->volume));
    // The 4 x 2 x 1 box itself, grown by the single-precision reach (7e-7 of the coordinates: under 1e-5 here).
    EXPECT_NEAR(volume(slab->volume), 8.0, 8.0 * 1e-4);
    EXPECT_NEAR((std::get<Obb>(slab->volume).center - Vec3(2, 1, 0.5)).norm(), 0.0, 1e-6);

    const Primitive* head = find(*imported, "USP_head");
    ASSERT_NE(head, nullptr);
    ASSERT_TRUE(std::holds_alternative<Sphere>(head->volume));
    EXPECT_NEAR(std::get<Sphere>(head->volume).radius, 1.0, 2e-5);
    EXPECT_NEAR((std::get<Sphere>(head->volume).center - Vec3(0, 0, 10)).norm(), 0.0, 1e-6);

    const Primitive* arm = find(*imported, "UCP_arm");
    ASSERT_NE(arm, nullptr);
    ASSERT_TRUE(std::holds_alternative<Capsule>(arm->volume));
    const Primitive* block = find(*imported, "UCX_block_01");
    ASSERT_NE(block, nullptr);
    // Every fitted primitive encloses its piece's vertices (spot checks of extreme ones).
    for (const Vec3& point : {Vec3(17, 0, 0), Vec3(10, 1, 0), Vec3(16, 0, -1)})
        EXPECT_TRUE(contains(arm->volume, Sphere{point, 0.0}, 1e-9));
    for (const Vec3& point : {Vec3(-10, -10, 0), Vec3(-8, -10, 0), Vec3(-10, -10, 2)})
        EXPECT_TRUE(contains(block->volume, Sphere{point, 0.0}, 1e-9));
}

TEST(MeshImport, GltfNodeTransformsAreApplied) {
    const Result<ImportResult> imported = import_mesh((test::test_data_dir() / "mesh_collision_convention.gltf").string());
    ASSERT_TRUE(imported.has_value()) << imported.error().to_string();
    ASSERT_EQ(imported->primitives.size(), 3u);
    // The unit cube [-1,1]^3, scaled (2,1,0.5) and moved to x = 10.
    const Primitive* crate = find(*imported, "UBX_crate");
    ASSERT_NE(crate, nullptr);
    const Obb& box = std::get<Obb>(crate->volume);
    EXPECT_NEAR((box.center - Vec3(10, 0, 0)).norm(), 0.0, 1e-6);
    EXPECT_NEAR(volume(crate->volume), 8.0 * 2.0 * 1.0 * 0.5, 8.0 * 1e-4);
    // A child node under a parent turned 90 degrees about z at z = 3: its local x offset becomes world y.
    const Primitive* child = find(*imported, "UBX_child");
    ASSERT_NE(child, nullptr);
    const Obb& child_box = std::get<Obb>(child->volume);
    EXPECT_NEAR((child_box.center - Vec3(0, 1, 3)).norm(), 0.0, 1e-6);
    EXPECT_NEAR(volume(child->volume), 8.0 * 3.0, 24.0 * 1e-4);
    EXPECT_NEAR(world_aabb(child->volume).half_extents().y(), 3.0, 2e-5);
    const Primitive* ball = find(*imported, "USP_ball");
    ASSERT_NE(ball, nullptr);
    EXPECT_NEAR(std::get<Sphere>(ball->volume).radius, std::sqrt(3.0), 2e-5);
}

TEST(MeshImport, PlainMeshNeedsOnePrimitivePerMesh) {
    const std::string file = (test::test_data_dir() / "mesh_plain.gltf").string();
    const Result<ImportResult> refused = import_mesh(file);
    ASSERT_FALSE(refused.has_value());
    EXPECT_NE(refused.error().message.find("one_primitive_per_mesh"), std::string::npos);
    MeshImportOptions options;
    options.one_primitive_per_mesh = true;
    const Result<ImportResult> imported = import_mesh(file, options);
    ASSERT_TRUE(imported.has_value()) << imported.error().to_string();
    ASSERT_EQ(imported->primitives.size(), 2u);
    EXPECT_EQ(imported->primitives[0].name, "left");
    // A cube's best fit is the cube (an AABB or OBB of volume 8).
    EXPECT_NEAR(volume(imported->primitives[0].volume), 8.0, 8.0 * 1e-4);
    EXPECT_NEAR(world_aabb(imported->primitives[1].volume).center().x(), 3.0, 1e-6);
}

TEST(MeshImport, FitsEncloseTheFilesVerticesNotOnlyTheirSinglePrecisionCopies) {
    // assimp reads single precision: at 10^6 a float steps by 0.0625, so these vertices 0.01 apart all read as
    // 1e6, and a fit of what assimp gives was a box 1e-15 wide at x = 1e6 that missed the file's vertices by 0.02.
    const fs::path file = fs::temp_directory_path() / ("hbvh_far_" + std::to_string(::getpid()) + ".obj");
    std::ofstream(file) << "o UBX_a\nv 1000000.01 0 0\nv 1000000.02 0 0\nv 1000000.01 1 0\nv 1000000.01 0 1\n"
                           "f 1 2 3\nf 1 2 4\n";
    const Result<ImportResult> imported = import_mesh(file.string());
    fs::remove(file);
    ASSERT_TRUE(imported.has_value()) << imported.error().to_string();
    ASSERT_EQ(imported->primitives.size(), 1u);
    for (const Vec3& vertex : {Vec3(1000000.01, 0, 0), Vec3(1000000.02, 0, 0), Vec3(1000000.01, 1, 0), Vec3(1000000.01, 0, 1)})
        EXPECT_TRUE(contains(imported->primitives[0].volume, Sphere{vertex, 0.0}, 0.0)) << vertex.transpose();
    // And no more than the documented reach: 4 float ulps at 10^6 (0.0625 each), times sqrt(3), on each side.
    EXPECT_LT(world_aabb(imported->primitives[0].volume).half_extents().x(), 0.01 + 4 * 0.0625 * std::sqrt(3.0) + 1e-9);
}

TEST(MeshImport, SharedMeshesFitAsOnePrimitive) {
    const fs::path folder = test::shared_meshes_dir();
    if (!fs::exists(folder / "stanford_bunny.obj")) GTEST_SKIP() << "no shared meshes at " << folder;
    MeshImportOptions options;
    options.one_primitive_per_mesh = true;
    for (const char* name : {"stanford_bunny.obj", "mujoco_mug.obj"}) {
        const Result<ImportResult> imported = import_mesh((folder / name).string(), options);
        ASSERT_TRUE(imported.has_value()) << imported.error().to_string();
        ASSERT_EQ(imported->primitives.size(), 1u) << name;
        // The mug is 12.3 x 7.2 x 8.9 cm (README): its fit lies between its AABB's inscribed ball and the AABB.
        const Aabb box = world_aabb(imported->primitives[0].volume);
        EXPECT_GT(box.volume(), 0.0);
        if (std::string(name) == "mujoco_mug.obj") {
            EXPECT_LE(volume(imported->primitives[0].volume), 12.32 * 7.19 * 8.94 * 1.001);
            EXPECT_LE(box.min.x(), -4.47 + 1e-6);
            EXPECT_GE(box.max.x(), 7.85 - 1e-6);
        }
    }
}

TEST(MeshImport, ErrorsNameTheFile) {
    const fs::path folder = fs::temp_directory_path() / "hbvh_mesh_errors";
    fs::create_directories(folder);
    const Result<ImportResult> missing = import_mesh((folder / "absent.obj").string());
    ASSERT_FALSE(missing.has_value());
    EXPECT_EQ(missing.error().file, (folder / "absent.obj").string());
    const fs::path garbage = folder / "garbage.gltf";
    std::ofstream(garbage) << "{ this is not json";
    const Result<ImportResult> bad = import_mesh(garbage.string());
    ASSERT_FALSE(bad.has_value());
    EXPECT_NE(bad.error().message.find("cannot read mesh"), std::string::npos);
    fs::remove_all(folder);
}

}  // namespace
}  // namespace hbvh
