// SPDX-License-Identifier: MIT
// URDF importer tests: a hand-computed chain, the shared real robots, a cross-format check and errors.
#include "hbvh/io/urdf.hpp"

#include <fstream>

#include <gtest/gtest.h>

#include "hbvh/io/mjcf.hpp"
#include "hbvh/io/solid_shapes.hpp"
#include "io/import_test_support.hpp"

namespace hbvh {
namespace {

namespace fs = std::filesystem;

TEST(Urdf, ChainPosesAreComposedAtZeroJointValues) {
    const Result<ImportResult> imported = import_urdf((test::test_data_dir() / "urdf_chain.urdf").string());
    ASSERT_TRUE(imported.has_value()) << imported.error().to_string();
    const auto& p = imported->primitives;
    ASSERT_EQ(p.size(), 4u);
    // base: a box of full size 0.2 x 0.4 x 0.6 at the origin, and a ball 1 m along x.
    EXPECT_EQ(test::compare_volumes(p[0].volume, Obb{Vec3::Zero(), Mat3::Identity(), Vec3(0.1, 0.2, 0.3)}, 1e-12), "");
    EXPECT_EQ(p[0].name, "base_collision0");
    EXPECT_EQ(test::compare_volumes(p[1].volume, Sphere{Vec3(1, 0, 0), 0.5}, 1e-12), "");
    EXPECT_EQ(p[1].name, "ball");
    // arm = translate (0,0,1) then yaw 90 deg; its cylinder sits at arm (1,0,0) = world (0,1,1), and roll 90 deg
    // takes its z axis to arm -y = world +x. Radius 0.05, length 1: long, so the capsule rule applies.
    const RigidTransform cylinder_frame{Mat3(Eigen::AngleAxisd(std::numbers::pi / 2, Vec3::UnitZ()) *
                                             Eigen::AngleAxisd(std::numbers::pi / 2, Vec3::UnitX())),
                                        Vec3(0, 1, 1)};
    EXPECT_NEAR(cylinder_frame.rotation.col(2).x(), 1.0, 1e-12);
    EXPECT_EQ(test::compare_volumes(p[2].volume, enclose_cylinder(cylinder_frame, 0.05, 0.5), 1e-12), "");
    ASSERT_TRUE(std::holds_alternative<Capsule>(p[2].volume));
    EXPECT_NEAR(std::abs(std::get<Capsule>(p[2].volume).direction().x()), 1.0, 1e-12);
    // tip = arm * (translate (2,0,0), pitch 90 deg): origin (0,2,1), z axis to arm +x = world +y.
    EXPECT_EQ(test::compare_volumes(p[3].volume, Capsule{Vec3(0, 1.8, 1), Vec3(0, 2.2, 1), 0.1}, 1e-12), "");
    EXPECT_EQ(p[3].name, "finger");
    // The mesh and the zero-radius placeholder are reported with their lines.
    ASSERT_EQ(imported->warnings.size(), 2u);
    EXPECT_NE(imported->warnings[0].find("urdf_chain.urdf:26:"), std::string::npos) << imported->warnings[0];
    EXPECT_NE(imported->warnings[0].find("finger.dae"), std::string::npos);
    EXPECT_NE(imported->warnings[1].find("placeholder"), std::string::npos);
}

TEST(Urdf, SharedRobotsHaveTheDocumentedCounts) {
    const fs::path folder = test::shared_models_dir();
    if (!fs::exists(folder)) GTEST_SKIP() << "no shared models at " << folder;
    const std::vector<std::tuple<std::string, std::size_t, std::size_t>> counts{
        {"anybotics_anymal_b_simple.urdf", 40, 0},
        {"urdf_tutorial_r2d2_physics.urdf", 12, 4},
        {"drake_franka_panda_arm_hand_spheres.urdf", 66, 0},
        {"drake_tri_homecart_bimanual.urdf", 26, 0}};
    for (const auto& [name, primitive_count, mesh_count] : counts) {
        const Result<ImportResult> imported = import_urdf((folder / name).string());
        ASSERT_TRUE(imported.has_value()) << imported.error().to_string();
        EXPECT_EQ(imported->primitives.size(), primitive_count) << name;
        EXPECT_EQ(imported->warnings.size(), mesh_count) << name;
    }
}

// The same ANYmal B in both formats: undo the MJCF base pose (z + 0.58 m, half turn about z) and the 40 centres and
// kinds agree. Sizes are not compared: the menagerie port changed 8 of them (shared models README).
TEST(Urdf, AnymalMatchesItsMjcfTwin) {
    const fs::path folder = test::shared_models_dir();
    if (!fs::exists(folder)) GTEST_SKIP() << "no shared models at " << folder;
    const Result<ImportResult> urdf = import_urdf((folder / "anybotics_anymal_b_simple.urdf").string());
    const Result<ImportResult> mjcf = import_mjcf((folder / "menagerie_anybotics_anymal_b.xml").string());
    ASSERT_TRUE(urdf.has_value() && mjcf.has_value());
    ASSERT_EQ(urdf->primitives.size(), mjcf->primitives.size());
    const RigidTransform base{Mat3(Vec3(-1, -1, 1).asDiagonal()), Vec3(0, 0, 0.58)};
    for (const Primitive& u : urdf->primitives) {
        const Vec3 centre = base.apply(world_aabb(u.volume).center());
        bool found = false;
        for (const Primitive& m : mjcf->primitives)
            found = found || ((world_aabb(m.volume).center() - centre).norm() < 1e-9 && m.volume.index() == u.volume.index());
        EXPECT_TRUE(found) << u.name;
    }
}

// Only a point is a placeholder: a plate (a box with one zero size), a disc (a cylinder of length 0), a rod (a cylinder
// of radius 0) and a segment (a capsule of radius 0) have real extent and are kept as flat or thin primitives, which
// the library and both file formats hold. Until 2026-12-07 any zero size dropped the shape.
TEST(Urdf, FlatAndThinShapesAreKeptAndOnlyPointsAreSkipped) {
    const fs::path folder = fs::temp_directory_path() / "hbvh_urdf_flat";
    fs::create_directories(folder);
    const fs::path file = folder / "flat.urdf";
    std::ofstream(file) << "<robot name=\"r\">\n<link name=\"base\">\n"
                           "<collision name=\"plate\"><geometry><box size=\"1 2 0\"/></geometry></collision>\n"
                           "<collision name=\"disc\"><origin xyz=\"3 0 0\"/><geometry><cylinder radius=\"0.5\" length=\"0\"/>"
                           "</geometry></collision>\n"
                           "<collision name=\"rod\"><origin xyz=\"0 3 0\"/><geometry><cylinder radius=\"0\" length=\"2\"/>"
                           "</geometry></collision>\n"
                           "<collision name=\"dot\"><geometry><sphere radius=\"0\"/></geometry></collision>\n"
                           "<collision name=\"nothing\"><geometry><box size=\"0 0 0\"/></geometry></collision>\n"
                           "</link>\n</robot>\n";
    const Result<ImportResult> imported = import_urdf(file.string());
    ASSERT_TRUE(imported.has_value()) << imported.error().to_string();
    const auto& p = imported->primitives;
    ASSERT_EQ(p.size(), 3u);
    EXPECT_EQ(p[0].name, "plate");
    EXPECT_EQ(test::compare_volumes(p[0].volume, Obb{Vec3::Zero(), Mat3::Identity(), Vec3(0.5, 1.0, 0.0)}, 1e-12), "");
    EXPECT_EQ(p[1].name, "disc");
    EXPECT_EQ(test::compare_volumes(p[1].volume, Obb{Vec3(3, 0, 0), Mat3::Identity(), Vec3(0.5, 0.5, 0.0)}, 1e-12), "");
    EXPECT_EQ(p[2].name, "rod");
    EXPECT_EQ(test::compare_volumes(p[2].volume, Capsule{Vec3(0, 3, -1), Vec3(0, 3, 1), 0.0}, 1e-12), "");
    ASSERT_EQ(imported->warnings.size(), 2u);
    EXPECT_NE(imported->warnings[0].find("flat.urdf:6: sphere 'dot' has zero size (a point)"), std::string::npos)
        << imported->warnings[0];
    EXPECT_NE(imported->warnings[1].find("flat.urdf:7: box 'nothing' has zero size (a point)"), std::string::npos)
        << imported->warnings[1];
    fs::remove_all(folder);
}

TEST(Urdf, ErrorsNameFileLineAndProblem) {
    const fs::path folder = fs::temp_directory_path() / "hbvh_urdf_errors";
    fs::create_directories(folder);
    struct Case {
        std::string text;
        int line;
        std::string problem;
    };
    const std::vector<Case> cases{
        {"<robot name=\"r\">\n<link name=\"a\">\n</robot>", 3, "malformed XML"},
        {"<mujoco>\n</mujoco>", 1, "expected <robot>"},
        {"<robot name=\"r\">\n<link name=\"a\"/>\n<joint name=\"j\" type=\"fixed\">\n<parent link=\"a\"/>"
         "<child link=\"missing\"/></joint>\n</robot>",
         3, "urdfdom rejected"},
        {"<robot name=\"r\">\n<link name=\"a\"><collision><geometry>\n<capsule radius=\"x\" length=\"1\"/>"
         "</geometry></collision></link>\n</robot>",
         3, "capsule radius"},
        // Numbers urdfdom would refuse only as "a different number of collisions", told with their line.
        {"<robot name=\"r\">\n<link name=\"a\"><collision><geometry>\n<box size=\"1 2\"/>"
         "</geometry></collision></link>\n</robot>",
         3, "<box> attribute 'size' needs 3 finite numbers, found \"1 2\""},
        {"<robot name=\"r\">\n<link name=\"a\"><collision>\n<origin xyz=\"nan 0 0\"/><geometry><sphere radius=\"1\"/>"
         "</geometry></collision></link>\n</robot>",
         3, "<origin> attribute 'xyz' needs 3 finite numbers"},
        {"<robot name=\"r\">\n<link name=\"a\"><collision><geometry>\n<cylinder radius=\"-1\" length=\"1\"/>"
         "</geometry></collision></link>\n</robot>",
         3, "<cylinder> attribute 'radius' must not be negative"},
        {"<robot name=\"r\">\n<link>\n</link>\n</robot>", 2, "<link> without a name"},
        // What urdfdom drops, with its own reason (the message blamed "a different number of collisions").
        {"<robot name=\"r\">\n<link name=\"a\">\n<collision><geometry><sphere radius=\"1\"/></geometry></collision>"
         "<collision><geometry><mesh/></geometry></collision></link>\n</robot>",
         2, "urdfdom read 1 of the 2 collisions of link 'a': Mesh must contain a filename attribute"},
        {"<robot name=\"r\">\n<link name=\"a\">\n<inertial><mass value=\"-abc\"/></inertial>"
         "<collision><geometry><sphere radius=\"1\"/></geometry></collision></link>\n</robot>",
         2, "mass [-abc] is not a float"},
        {"<robot name=\"r\">\n<link name=\"a\"/>\n<link name=\"b\"/>\n<joint name=\"j\" type=\"fixed\">\n"
         "<parent link=\"a\"/><child link=\"b\"/>\n<origin xyz=\"0 0\"/></joint>\n</robot>",
         6, "<origin> attribute 'xyz' needs 3 finite numbers, found \"0 0\""},
    };
    for (std::size_t i = 0; i < cases.size(); ++i) {
        const fs::path file = folder / ("case" + std::to_string(i) + ".urdf");
        std::ofstream(file) << cases[i].text;
        const Result<ImportResult> imported = import_urdf(file.string());
        ASSERT_FALSE(imported.has_value()) << cases[i].text;
        EXPECT_EQ(imported.error().file, file.string());
        EXPECT_EQ(imported.error().line, cases[i].line) << imported.error().to_string();
        EXPECT_NE(imported.error().message.find(cases[i].problem), std::string::npos) << imported.error().to_string();
    }
    // An unknown shape is skipped with a warning rather than failing the whole robot.
    const fs::path cone = folder / "cone.urdf";
    std::ofstream(cone) << "<robot name=\"r\">\n<link name=\"a\">\n<collision><geometry><cone radius=\"1\"/>"
                           "</geometry></collision>\n<collision><geometry><sphere radius=\"1\"/></geometry>"
                           "</collision></link>\n</robot>";
    const Result<ImportResult> imported = import_urdf(cone.string());
    ASSERT_TRUE(imported.has_value()) << imported.error().to_string();
    EXPECT_EQ(imported->primitives.size(), 1u);
    ASSERT_EQ(imported->warnings.size(), 1u);
    EXPECT_NE(imported->warnings[0].find("cone.urdf:3: collision with unknown geometry <cone>"), std::string::npos)
        << imported->warnings[0];
    // Blanks around a number, which urdfdom refuses, are read: the number is handed on in a form it takes.
    const fs::path padded = folder / "padded.urdf";
    std::ofstream(padded) << "<robot name=\"r\">\n<link name=\"a\"><collision><origin xyz=\" 1 2 3 \"/><geometry>"
                             "<sphere radius=\" 0.5 \"/></geometry></collision></link>\n</robot>";
    const Result<ImportResult> blanks = import_urdf(padded.string());
    ASSERT_TRUE(blanks.has_value()) << blanks.error().to_string();
    ASSERT_EQ(blanks->primitives.size(), 1u);
    EXPECT_EQ(std::get<Sphere>(blanks->primitives[0].volume).radius, 0.5);
    EXPECT_EQ(std::get<Sphere>(blanks->primitives[0].volume).center, Vec3(1, 2, 3));
    // A second shape in one <geometry> is dropped by urdfdom: the import says so, at the geometry's line. The first
    // is read also when a <capsule> follows (the capsule replaced the box).
    const auto import_two_shapes = [&](const std::string& name, const std::string& shapes) {
        const fs::path file = folder / name;
        std::ofstream(file) << "<robot name=\"r\">\n<link name=\"a\">\n<collision>\n<geometry>" << shapes
                            << "</geometry>\n</collision></link>\n</robot>";
        const Result<ImportResult> read = import_urdf(file.string());
        EXPECT_TRUE(read.has_value()) << read.error().to_string();
        if (read) {
            EXPECT_EQ(read->primitives.size(), 1u);
            EXPECT_EQ(read->warnings.size(), 1u);
        }
        return read;
    };
    const Result<ImportResult> first_only = import_two_shapes("two.urdf", "<sphere radius=\"1\"/><box size=\"1 1 1\"/>");
    ASSERT_TRUE(first_only.has_value() && first_only->primitives.size() == 1 && first_only->warnings.size() == 1);
    EXPECT_TRUE(std::holds_alternative<Sphere>(first_only->primitives[0].volume));
    EXPECT_NE(first_only->warnings[0].find("two.urdf:4: <geometry> holds 2 shapes; only the first, <sphere>, is read"),
              std::string::npos)
        << first_only->warnings[0];
    const Result<ImportResult> box_first =
        import_two_shapes("two_shapes.urdf", "<box size=\"1 1 1\"/><capsule radius=\"0.1\" length=\"0.5\"/>");
    ASSERT_TRUE(box_first.has_value() && box_first->primitives.size() == 1 && box_first->warnings.size() == 1);
    EXPECT_TRUE(std::holds_alternative<Obb>(box_first->primitives[0].volume));
    EXPECT_NE(box_first->warnings[0].find("two_shapes.urdf:4: <geometry> holds 2 shapes; only the first, <box>, is read"),
              std::string::npos)
        << box_first->warnings[0];
    fs::remove_all(folder);
}

}  // namespace
}  // namespace hbvh
