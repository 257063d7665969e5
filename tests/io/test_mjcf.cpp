// SPDX-License-Identifier: MIT
// MJCF importer tests: MuJoCo 2.2.2 as the oracle for every file it loads, plus hand-checked cases and errors.
#include "hbvh/io/mjcf.hpp"

#include <cmath>
#include <fstream>
#include <optional>
#include <random>
#include <set>

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>
#include <pugixml.hpp>

#include "hbvh/io/solid_shapes.hpp"
#include "io/import_test_support.hpp"

namespace hbvh {
namespace {

namespace fs = std::filesystem;
using test::compare_volumes;
using test::describe;

// A collision geom as MuJoCo compiled it: world pose after mj_forward, type and size.
struct OracleGeom {
    int type = 0;
    RigidTransform world;
    Vec3 size = Vec3::Zero();
};

// A temporary folder removed at the end of the test.
struct TempDir {
    fs::path path;
    TempDir() {
        std::random_device device;
        path = fs::temp_directory_path() / ("hbvh_mjcf_" + std::to_string(device()) + std::to_string(device()));
        fs::create_directories(path);
    }
    ~TempDir() {
        std::error_code ignored;
        fs::remove_all(path, ignored);
    }
};

// Loads `path` with MuJoCo and returns its non-mesh collision geoms in model order; nullopt when MuJoCo refuses.
std::optional<std::vector<OracleGeom>> load_with_mujoco(const fs::path& path, std::string& message) {
    char error[1000] = "";
    mjModel* model = mj_loadXML(path.c_str(), nullptr, error, sizeof(error));
    if (model == nullptr) {
        message = error;
        return std::nullopt;
    }
    mjData* data = mj_makeData(model);
    // Positions and orientations are all the oracle needs; mj_kinematics is the part of mj_forward that sets them.
    mj_kinematics(model, data);
    std::vector<OracleGeom> geoms;
    for (int i = 0; i < model->ngeom; ++i) {
        const int type = model->geom_type[i];
        if (model->geom_contype[i] == 0 && model->geom_conaffinity[i] == 0) continue;
        if (type == mjGEOM_PLANE || type == mjGEOM_HFIELD || type == mjGEOM_MESH) continue;
        OracleGeom geom;
        geom.type = type;
        for (int r = 0; r < 3; ++r) {
            geom.world.translation[r] = data->geom_xpos[3 * i + r];
            geom.size[r] = model->geom_size[3 * i + r];
            for (int c = 0; c < 3; ++c) geom.world.rotation(r, c) = data->geom_xmat[9 * i + 3 * r + c];
        }
        geoms.push_back(geom);
    }
    mj_deleteData(data);
    mj_deleteModel(model);
    return geoms;
}

// The volume our rules give for a geom MuJoCo compiled: the same mapping as the importer, from MuJoCo's numbers.
BoundingVolume expected_volume(const OracleGeom& geom) {
    const Vec3 axis = geom.world.rotation.col(2);
    switch (geom.type) {
        case mjGEOM_SPHERE: return Sphere{geom.world.translation, geom.size[0]};
        case mjGEOM_CAPSULE:
            return Capsule{geom.world.translation - geom.size[1] * axis, geom.world.translation + geom.size[1] * axis,
                           geom.size[0]};
        case mjGEOM_BOX: return Obb{geom.world.translation, geom.world.rotation, geom.size};
        case mjGEOM_CYLINDER: return enclose_cylinder(geom.world, geom.size[0], geom.size[1]);
        case mjGEOM_ELLIPSOID: return enclose_ellipsoid(geom.world, geom.size);
        default: ADD_FAILURE() << "unexpected geom type " << geom.type; return Sphere{};
    }
}

// A tetrahedron with outward faces, so MuJoCo computes a positive mesh volume.
void write_dummy_mesh(const fs::path& path) {
    std::string extension = path.extension().string();
    for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    std::ofstream out(path, std::ios::binary);
    const float v[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    const int faces[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
    if (extension == ".stl") {
        char header[80] = {};
        out.write(header, 80);
        const std::uint32_t count = 4;
        out.write(reinterpret_cast<const char*>(&count), 4);
        for (const auto& face : faces) {
            const float normal[3] = {0, 0, 0};
            out.write(reinterpret_cast<const char*>(normal), sizeof(normal));
            for (int corner : face) out.write(reinterpret_cast<const char*>(v[corner]), 3 * sizeof(float));
            const std::uint16_t attributes = 0;
            out.write(reinterpret_cast<const char*>(&attributes), 2);
        }
    } else {
        for (const auto& vertex : v) out << "v " << vertex[0] << ' ' << vertex[1] << ' ' << vertex[2] << '\n';
        for (const auto& face : faces) out << "f " << face[0] + 1 << ' ' << face[1] + 1 << ' ' << face[2] + 1 << '\n';
    }
}

// Copies an MJCF file (and the files it includes) into `folder` in a form MuJoCo 2.2.2 accepts quickly without
// changing any geom: attributes newer than 2.2.2 removed, <size> dropped (njmax/nstack arenas cost up to 20 s in
// mj_makeData and say nothing about geometry), textures and skins dropped, and every referenced mesh replaced by a
// dummy tetrahedron. Includes are resolved against the main file's folder, as MuJoCo does.
bool write_oracle_copy(const fs::path& source, const fs::path& main_folder, const fs::path& target, int& mesh_count) {
    pugi::xml_document document;
    if (!document.load_file(source.c_str())) return false;
    const pugi::xml_node root = document.document_element();
    for (const char* attribute : {"assetdir", "meshdir", "texturedir"}) root.child("compiler").remove_attribute(attribute);
    for (const char* attribute : {"realtime", "cameraid"}) root.child("visual").child("global").remove_attribute(attribute);
    if (std::string_view(root.child("option").attribute("integrator").value()) == "implicitfast")
        root.child("option").remove_attribute("integrator");
    root.child("option").child("flag").remove_attribute("nativeccd");
    std::vector<pugi::xml_node> doomed;
    for (pugi::xpath_node hit : document.select_nodes("//texture | //skin | /mujoco/size")) doomed.push_back(hit.node());
    for (pugi::xml_node node : doomed) node.parent().remove_child(node);
    for (pugi::xpath_node hit : document.select_nodes("//material")) hit.node().remove_attribute("texture");
    for (pugi::xpath_node hit : document.select_nodes("//asset/mesh[@file]")) {
        const fs::path original = hit.node().attribute("file").value();
        // An unnamed mesh is named after its file, so keep that name when the file is replaced.
        if (!hit.node().attribute("name")) hit.node().append_attribute("name").set_value(original.stem().c_str());
        const std::string name = "dummy" + std::to_string(mesh_count++) + original.extension().string();
        write_dummy_mesh(target.parent_path() / name);
        hit.node().attribute("file").set_value(name.c_str());
    }
    for (pugi::xpath_node hit : document.select_nodes("//include[@file]")) {
        const fs::path relative = hit.node().attribute("file").value();
        const fs::path included_target = target.parent_path() / relative;
        fs::create_directories(included_target.parent_path());
        if (!write_oracle_copy(main_folder / relative, main_folder, included_target, mesh_count)) return false;
    }
    return document.save_file(target.c_str());
}

// Every MJCF file the oracle sees: our own test models first, then the Debian samples and the shared models.
// Include fragments are left out, and so are byte-identical copies (three shared models are Debian samples).
std::vector<fs::path> oracle_candidates() {
    std::vector<fs::path> files;
    for (const char* name : {"mjcf_defaults.xml", "mjcf_orientations.xml", "mjcf_fromto.xml", "mjcf_include_main.xml",
                             "mjcf_named_root_default.xml"})
        files.push_back(test::test_data_dir() / name);
    std::vector<fs::path> found;
    for (const fs::path& folder : {fs::path("/usr/share/mujoco/model"), test::shared_models_dir()}) {
        if (!fs::exists(folder)) continue;
        for (const auto& entry : fs::recursive_directory_iterator(folder))
            if (entry.path().extension() == ".xml" && entry.path().filename() != "humanoid_body.xml" &&
                entry.path().filename() != "scene.xml")
                found.push_back(entry.path());
    }
    std::sort(found.begin(), found.end());
    std::set<std::string> seen_contents;
    for (const fs::path& file : found) {
        std::ifstream stream(file, std::ios::binary);
        const std::string contents((std::istreambuf_iterator<char>(stream)), std::istreambuf_iterator<char>());
        if (seen_contents.insert(contents).second) files.push_back(file);
    }
    return files;
}

// One test per file, so that ctest runs them in parallel and a failure names the file.
class MjcfOracle : public ::testing::TestWithParam<fs::path> {};

TEST_P(MjcfOracle, MatchesMuJoCo) {
    const fs::path& file = GetParam();
    const Result<ImportResult> imported = import_mjcf(file.string());
    ASSERT_TRUE(imported.has_value()) << imported.error().to_string();
    // Generated geometry (<composite>) exists in MuJoCo's model but not in ours; the importer says so. These
    // models are also the slowest to compile (particle.xml takes 30 s), so they are not given to MuJoCo.
    for (const std::string& warning : imported->warnings) {
        if (warning.find("<composite>") == std::string::npos) continue;
        EXPECT_NE(file.string().find("/usr/share/mujoco/"), std::string::npos) << "unexpected <composite>";
        std::cout << "[ oracle  ] " << file.filename().string() << ": not compared, uses <composite>\n";
        return;
    }
    std::string why = "cannot write the clean copy";
    std::optional<std::vector<OracleGeom>> oracle;
    TempDir folder;
    int mesh_count = 0;
    if (write_oracle_copy(file, file.parent_path(), folder.path / file.filename(), mesh_count))
        oracle = load_with_mujoco(folder.path / file.filename(), why);
    if (!oracle) {
        // MuJoCo 2.2.2 refuses the file even after clean-up: at least the import must find geometry.
        EXPECT_GT(imported->primitives.size(), 0u) << "MuJoCo: " << why;
        std::cout << "[ oracle  ] " << file.filename().string() << ": MuJoCo refuses (" << why << "), imported "
                  << imported->primitives.size() << " primitives\n";
        return;
    }
    ASSERT_EQ(imported->primitives.size(), oracle->size());
    for (std::size_t i = 0; i < oracle->size(); ++i) {
        const BoundingVolume expected = expected_volume((*oracle)[i]);
        const BoundingVolume& actual = imported->primitives[i].volume;
        EXPECT_EQ(compare_volumes(actual, expected, 1e-9), "")
            << "geom " << i << " '" << imported->primitives[i].name << "': got " << describe(actual) << ", MuJoCo "
            << describe(expected);
    }
    std::cout << "[ oracle  ] " << file.filename().string() << ": " << oracle->size() << " geoms match MuJoCo\n";
}

INSTANTIATE_TEST_SUITE_P(Files, MjcfOracle, ::testing::ValuesIn(oracle_candidates()),
                         [](const ::testing::TestParamInfo<fs::path>& param_info) {
                             std::string name = param_info.param.stem().string();
                             for (char& c : name)
                                 if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                             return name + "_" + std::to_string(param_info.index);
                         });

// MuJoCo 2.2.2 refuses these two as they are (attributes from MuJoCo 3); our importer must not.
TEST(Mjcf, ImportsFilesThatMuJoCo222Refuses) {
    const fs::path folder = test::shared_models_dir();
    if (!fs::exists(folder)) GTEST_SKIP() << "no shared models at " << folder;
    for (const char* name : {"dmc_duplo2x4.xml", "mujoco_cards.xml"}) {
        std::string why;
        EXPECT_FALSE(load_with_mujoco(folder / name, why).has_value()) << name;
        const Result<ImportResult> imported = import_mjcf((folder / name).string());
        ASSERT_TRUE(imported.has_value()) << imported.error().to_string();
        EXPECT_GT(imported->primitives.size(), 0u) << name;
    }
}

TEST(Mjcf, SharedModelsHaveTheDocumentedCounts) {
    const fs::path folder = test::shared_models_dir();
    if (!fs::exists(folder)) GTEST_SKIP() << "no shared models at " << folder;
    // From ../shared/data/models/README.md: collision primitives per file.
    const std::vector<std::pair<std::string, std::size_t>> counts{
        {"mujoco_humanoid.xml", 19}, {"mujoco_22_humanoids.xml", 418}, {"mujoco_mug.xml", 34},
        {"mujoco_cards.xml", 54}, {"dmc_rodent.xml", 100}, {"dmc_duplo2x4.xml", 21}, {"gymnasium_ant.xml", 13},
        {"menagerie_unitree_go1.xml", 42}, {"menagerie_wonik_allegro_right_hand.xml", 21},
        {"menagerie_anybotics_anymal_b.xml", 40}};
    for (const auto& [name, count] : counts) {
        const Result<ImportResult> imported = import_mjcf((folder / name).string());
        ASSERT_TRUE(imported.has_value()) << imported.error().to_string();
        EXPECT_EQ(imported->primitives.size(), count) << name;
    }
}

TEST(Mjcf, DefaultsFollowClassChildclassAndNesting) {
    const Result<ImportResult> imported = import_mjcf((test::test_data_dir() / "mjcf_defaults.xml").string());
    ASSERT_TRUE(imported.has_value()) << imported.error().to_string();
    const auto& p = imported->primitives;
    // ball, upper, thick_limb, block, half_ghost, forearm capsule, forearm block, 2 ellipsoids. No plane, site, ghost.
    ASSERT_EQ(p.size(), 9u);
    EXPECT_EQ(p[0].name, "ball");
    EXPECT_EQ(p[1].name, "upper");
    EXPECT_EQ(p[2].name, "arm_geom1");
    EXPECT_EQ(p[7].name, "body3_geom0");
    const auto& thick = std::get<Capsule>(p[2].volume);
    EXPECT_DOUBLE_EQ(thick.radius, 0.08);
    EXPECT_NEAR(thick.length(), 0.4, 1e-12);
    // The arm is turned 90 degrees about x, so its local z is world -y, its local y world z.
    EXPECT_NEAR((thick.center() - Vec3(0, 0, 1.1)).norm(), 0.0, 1e-12);
    EXPECT_NEAR(std::abs(thick.direction().y()), 1.0, 1e-12);
    EXPECT_TRUE(std::holds_alternative<Sphere>(p[4].volume));
    EXPECT_DOUBLE_EQ(std::get<Sphere>(p[4].volume).radius, 0.3);
}

TEST(Mjcf, CylinderAndEllipsoidRuleEnclosesTheShape) {
    // Sample the surface of each shape and check the chosen volume contains it.
    const RigidTransform frame{Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix(), Vec3(1, -2, 3)};
    for (const auto& [radius, half_length] : std::vector<std::pair<double, double>>{{1, 0.05}, {1, 1}, {1, 3}, {0.01, 2}}) {
        const BoundingVolume bv = enclose_cylinder(frame, radius, half_length);
        const Capsule capsule = enclosing_capsule_of_cylinder(frame, radius, half_length);
        EXPECT_LE(volume(bv), 8.0 * radius * radius * half_length + 1e-12);
        EXPECT_LE(capsule.radius, std::hypot(radius, half_length) + 1e-12);
        for (int k = 0; k < 64; ++k) {
            const double angle = 2.0 * std::numbers::pi * k / 64.0;
            for (double z : {-half_length, half_length}) {
                const Vec3 rim = frame.apply(Vec3(radius * std::cos(angle), radius * std::sin(angle), z));
                EXPECT_TRUE(contains(bv, Sphere{rim, 0.0}, 1e-12));
                EXPECT_TRUE(capsule.contains(Sphere{rim, 0.0}, 1e-12));
            }
        }
    }
    // Long thin cylinders become capsules, flat ones boxes.
    EXPECT_TRUE(std::holds_alternative<Capsule>(enclose_cylinder(frame, 0.01, 2)));
    EXPECT_TRUE(std::holds_alternative<Obb>(enclose_cylinder(frame, 1, 0.05)));
    for (const Vec3& axes : {Vec3(1, 2, 3), Vec3(3, 1, 1), Vec3(1, 1, 1), Vec3(0.1, 0.5, 0.2)}) {
        const BoundingVolume bv = enclose_ellipsoid(frame, axes);
        const Capsule capsule = enclosing_capsule_of_ellipsoid(frame, axes);
        std::mt19937 random(7);
        std::normal_distribution<double> normal;
        for (int k = 0; k < 500; ++k) {
            const Vec3 direction = Vec3(normal(random), normal(random), normal(random)).normalized();
            const Vec3 point = frame.apply(direction.cwiseProduct(axes));
            EXPECT_TRUE(contains(bv, Sphere{point, 0.0}, 1e-12));
            EXPECT_TRUE(capsule.contains(Sphere{point, 0.0}, 1e-12));
        }
    }
    // A sphere-shaped ellipsoid: the capsule degenerates to the sphere itself, which beats the cube.
    const BoundingVolume round = enclose_ellipsoid(frame, Vec3(1, 1, 1));
    ASSERT_TRUE(std::holds_alternative<Capsule>(round));
    EXPECT_NEAR(std::get<Capsule>(round).length(), 0.0, 1e-15);
}

// Known difference from MuJoCo 2.2.2, which lets a class's euler beat the geom's own quat: we follow recent
// MuJoCo, where the most specific orientation wins whole.
TEST(Mjcf, OwnOrientationReplacesTheClassOrientation) {
    const Result<ImportResult> imported = import_mjcf((test::test_data_dir() / "mjcf_orientation_priority.xml").string());
    ASSERT_TRUE(imported.has_value()) << imported.error().to_string();
    ASSERT_EQ(imported->primitives.size(), 2u);
    const Obb& own = std::get<Obb>(imported->primitives[0].volume);
    EXPECT_NEAR((own.rotation - Mat3(Vec3(1, -1, -1).asDiagonal())).norm(), 0.0, 1e-12);
    const Obb& inherited = std::get<Obb>(imported->primitives[1].volume);
    EXPECT_NEAR(inherited.rotation(1, 0), std::sqrt(0.5), 1e-12);
}

TEST(Mjcf, FrameElementComposes) {
    TempDir folder;
    const fs::path file = folder.path / "frame.xml";
    std::ofstream(file) << R"(<mujoco><worldbody><body pos="1 0 0">
        <frame pos="0 1 0" euler="0 0 90"><geom name="g" type="box" size="1 2 3" pos="1 0 0"/></frame>
        </body></worldbody></mujoco>)";
    const Result<ImportResult> imported = import_mjcf(file.string());
    ASSERT_TRUE(imported.has_value()) << imported.error().to_string();
    ASSERT_EQ(imported->primitives.size(), 1u);
    const Obb& box = std::get<Obb>(imported->primitives[0].volume);
    EXPECT_NEAR((box.center - Vec3(1, 2, 0)).norm(), 0.0, 1e-12);
    EXPECT_NEAR((box.rotation.col(0) - Vec3(0, 1, 0)).norm(), 0.0, 1e-12);
}

TEST(Mjcf, HugeOrientationNumbersTurnAsTheirDirectionSays) {
    // Every orientation form scaled by 1e155-1e300 (finite, but its square is not) turns as the unit form: a plain
    // norm overflowed, and the geoms came out unturned or with a matrix that is no rotation.
    TempDir folder;
    const auto box_axes = [&](const std::string& orientation) {
        const fs::path file = folder.path / "turned.xml";
        std::ofstream(file) << "<mujoco><worldbody><body " << orientation
                            << "><geom type=\"box\" size=\"1 2 3\"/></body></worldbody></mujoco>";
        const Result<ImportResult> imported = import_mjcf(file.string());
        EXPECT_TRUE(imported.has_value()) << orientation << ": " << imported.error().to_string();
        return imported ? std::get<Obb>(imported->primitives.at(0).volume).rotation : Mat3(Mat3::Zero());
    };
    const std::pair<const char*, const char*> same[] = {
        {R"(quat="1e160 0 0 1e160")", R"(quat="1 0 0 1")"},
        {R"(quat="1e300 1e300 0 0")", R"(quat="1 1 0 0")"},
        {R"(zaxis="1e160 0 0")", R"(zaxis="1 0 0")"},
        {R"(axisangle="1e155 0 0 90")", R"(axisangle="1 0 0 90")"},
        {R"(xyaxes="1e300 0 0 0 1e300 1e300")", R"(xyaxes="1 0 0 0 1 1")"},
    };
    for (const auto& [huge, unit] : same) {
        const Mat3 expected = box_axes(unit);
        EXPECT_LT((box_axes(huge) - expected).cwiseAbs().maxCoeff(), 1e-12) << huge;
        EXPECT_GT((expected - Mat3::Identity()).cwiseAbs().maxCoeff(), 0.5) << unit << " turns nothing";
    }
}

TEST(Mjcf, MeshGeomsAndGeneratorsAreReportedAndSkipped) {
    TempDir folder;
    const fs::path file = folder.path / "mesh.xml";
    std::ofstream(file) << "<mujoco>\n<asset><mesh name=\"m\" file=\"missing.stl\"/></asset>\n<worldbody>\n"
                           "<geom type=\"mesh\" mesh=\"m\"/>\n<geom type=\"box\" mesh=\"m\"/>\n"
                           "<geom type=\"mesh\" mesh=\"m\" contype=\"0\" conaffinity=\"0\"/>\n"
                           "<body><composite type=\"grid\" count=\"2 2 1\"/><geom size=\"1\"/></body>\n"
                           "</worldbody></mujoco>\n";
    const Result<ImportResult> imported = import_mjcf(file.string());
    ASSERT_TRUE(imported.has_value()) << imported.error().to_string();
    EXPECT_EQ(imported->primitives.size(), 1u);
    ASSERT_EQ(imported->warnings.size(), 3u);
    EXPECT_NE(imported->warnings[0].find("mesh.xml:4:"), std::string::npos) << imported->warnings[0];
    EXPECT_NE(imported->warnings[2].find("<composite>"), std::string::npos) << imported->warnings[2];
}

// Each malformed input gives its own error, located at the right line.
TEST(Mjcf, ErrorsNameFileLineAndProblem) {
    TempDir folder;
    struct Case {
        std::string text;
        int line;
        std::string problem;
    };
    const std::vector<Case> cases{
        {"<mujoco>\n<worldbody>\n<geom size=\"1\">\n</worldbody></mujoco>", 4, "malformed XML"},
        {"<robot>\n</robot>", 1, "expected <mujoco>"},
        {"<mujoco>\n<worldbody>\n<geom class=\"nope\" size=\"1\"/>\n</worldbody></mujoco>", 3, "unknown default class"},
        {"<mujoco>\n<worldbody>\n\n<geom size=\"1\" pos=\"1 x 2\"/>\n</worldbody></mujoco>", 4, "pos"},
        {"<mujoco>\n<worldbody>\n<geom type=\"box\" size=\"1 1\"/>\n</worldbody></mujoco>", 3, "positive size"},
        {"<mujoco>\n<worldbody>\n<body quat=\"1 0 0 0\" euler=\"0 0 1\"/>\n</worldbody></mujoco>", 3, "orientation"},
        {"<mujoco>\n<worldbody>\n<geom type=\"capsule\" size=\"1\" fromto=\"1 1 1 1 1 1\"/>\n</worldbody></mujoco>", 3,
         "fromto"},
        {"<mujoco>\n<worldbody>\n<geom type=\"cone\" size=\"1\"/>\n</worldbody></mujoco>", 3, "unknown geom type"},
        {"<mujoco>\n<worldbody>\n<geom type=\"sphere\" size=\"1\" fromto=\"0 0 0 1 0 0\"/>\n</worldbody></mujoco>", 3,
         "fromto needs a capsule, cylinder, box or ellipsoid, not a sphere"},
        {"<mujoco>\n<default>\n<geom fromto=\"0 0 0 1 0 0\"/>\n</default>\n<worldbody>\n<geom type=\"sphere\" size=\"1\"/>\n"
         "</worldbody></mujoco>", 3, "not a sphere"},
        {"<mujoco>\n<compiler angle=\"grad\"/>\n</mujoco>", 2, "angle"},
        {"<mujoco>\n<compiler coordinate=\"global\"/>\n</mujoco>", 2, "global"},
        {"<mujoco>\n<worldbody>\n<geom size=\"1\" quat=\"0 0 0 0\"/>\n</worldbody></mujoco>", 3, "degenerate"},
        {"<mujoco>\n<include file=\"absent.xml\"/>\n</mujoco>", 2, "cannot include"},
        {"<mujoco>\n<include file=\"bad.xml\"/>\n</mujoco>", 2, "bad.xml:1"},
    };
    std::ofstream(folder.path / "bad.xml") << "<mujoco><default>";
    for (std::size_t i = 0; i < cases.size(); ++i) {
        const fs::path file = folder.path / ("case" + std::to_string(i) + ".xml");
        std::ofstream(file) << cases[i].text;
        const Result<ImportResult> imported = import_mjcf(file.string());
        ASSERT_FALSE(imported.has_value()) << cases[i].text;
        EXPECT_EQ(imported.error().file, file.string());
        EXPECT_EQ(imported.error().line, cases[i].line) << imported.error().to_string();
        EXPECT_NE(imported.error().message.find(cases[i].problem), std::string::npos) << imported.error().to_string();
    }
    const Result<ImportResult> missing = import_mjcf((folder.path / "none.xml").string());
    ASSERT_FALSE(missing.has_value());
    EXPECT_NE(missing.error().message.find("cannot open"), std::string::npos);
}

// fromto sets the centre: a non-zero pos beside it, from the geom or its class, is refused as MuJoCo refuses it (until
// 2026-12-07 the pos was dropped without a word), and a zero pos is accepted as MuJoCo accepts it. MuJoCo is the
// oracle of each verdict; the error names the line of the pos and the place of the fromto.
TEST(Mjcf, PosBesideFromtoIsRefusedAsInMuJoCo) {
    struct Case {
        std::string text;
        int pos_line;  // 0: accepted
        int fromto_line;
    };
    const std::string rod_class = "<default>\n<default class=\"rod\">\n<geom type=\"capsule\" size=\"0.02\" "
                                  "fromto=\"0 0 0 0 0 -0.5\"/>\n</default>\n</default>\n";
    const std::vector<Case> cases{
        {"<mujoco>\n<worldbody>\n<geom type=\"capsule\" size=\"0.02\" fromto=\"0 0 0 0 0 -0.5\" pos=\"1 2 3\"/>\n"
         "</worldbody>\n</mujoco>", 3, 3},
        {"<mujoco>\n" + rod_class + "<worldbody>\n<geom class=\"rod\" pos=\"0 0 0.1\"/>\n</worldbody>\n</mujoco>", 8, 4},
        {"<mujoco>\n<default>\n<default class=\"p\">\n<geom type=\"capsule\" size=\"0.02\" pos=\"1 0 0\"/>\n</default>\n"
         "</default>\n<worldbody>\n<geom class=\"p\" fromto=\"0 0 0 0 0 -0.5\"/>\n</worldbody>\n</mujoco>", 4, 8},
        {"<mujoco>\n<worldbody>\n<geom type=\"capsule\" size=\"0.02\" fromto=\"0 0 0 0 0 -0.5\" pos=\"0 0 0\"/>\n"
         "</worldbody>\n</mujoco>", 0, 3},
        {"<mujoco>\n" + rod_class + "<worldbody>\n<geom class=\"rod\" euler=\"10 0 0\"/>\n</worldbody>\n</mujoco>", 0, 4},
    };
    TempDir folder;
    for (std::size_t i = 0; i < cases.size(); ++i) {
        const fs::path file = folder.path / ("case" + std::to_string(i) + ".xml");
        std::ofstream(file) << cases[i].text;
        std::string why;
        const bool mujoco_accepts = load_with_mujoco(file, why).has_value();
        const Result<ImportResult> imported = import_mjcf(file.string());
        EXPECT_EQ(imported.has_value(), mujoco_accepts) << cases[i].text << "\nMuJoCo: " << why;
        EXPECT_EQ(imported.has_value(), cases[i].pos_line == 0) << cases[i].text;
        if (imported.has_value()) {
            ASSERT_EQ(imported->primitives.size(), 1u);
            const auto* capsule = std::get_if<Capsule>(&imported->primitives[0].volume);
            ASSERT_NE(capsule, nullptr);
            EXPECT_NEAR(0.5 * (capsule->p0 + capsule->p1).z(), -0.25, 1e-12);  // the segment's middle, not pos
            continue;
        }
        EXPECT_EQ(imported.error().line, cases[i].pos_line) << imported.error().to_string();
        EXPECT_NE(imported.error().message.find("pos and fromto (at " + file.string() + ":" +
                                                std::to_string(cases[i].fromto_line) + ") are both given"),
                  std::string::npos)
            << imported.error().to_string();
    }
}

TEST(Mjcf, AbsurdNestingIsAnErrorNotACrash) {
    TempDir folder;
    std::string text = "<mujoco><worldbody>";
    for (int i = 0; i < 5000; ++i) text += "<body>";
    for (int i = 0; i < 5000; ++i) text += "</body>";
    text += "</worldbody><default>";
    std::ofstream(folder.path / "deep.xml") << text << "</default></mujoco>";
    const Result<ImportResult> imported = import_mjcf((folder.path / "deep.xml").string());
    ASSERT_FALSE(imported.has_value());
    EXPECT_NE(imported.error().message.find("nested"), std::string::npos) << imported.error().to_string();
}

TEST(Mjcf, ModelWithoutWorldbodyIsEmptyWithAWarning) {
    TempDir folder;
    std::ofstream(folder.path / "empty.xml") << "<mujoco><option timestep=\"0.01\"/></mujoco>";
    const Result<ImportResult> imported = import_mjcf((folder.path / "empty.xml").string());
    ASSERT_TRUE(imported.has_value()) << imported.error().to_string();
    EXPECT_TRUE(imported->primitives.empty());
    ASSERT_EQ(imported->warnings.size(), 1u);
}

TEST(Mjcf, IncludeCycleIsAnError) {
    TempDir folder;
    std::ofstream(folder.path / "a.xml") << "<mujoco><include file=\"b.xml\"/></mujoco>";
    std::ofstream(folder.path / "b.xml") << "<mujoco><include file=\"a.xml\"/></mujoco>";
    const Result<ImportResult> imported = import_mjcf((folder.path / "a.xml").string());
    ASSERT_FALSE(imported.has_value());
    EXPECT_NE(imported.error().message.find("included a second time"), std::string::npos) << imported.error().to_string();
}

TEST(Mjcf, MisspeltElementsAndAttributesAreWarnedOf) {
    // MuJoCo refuses what its schema does not know; the importer reads on, but says what it skipped (a misspelt
    // <bdoy> lost its geoms, `eular` left a body unturned, without a word).
    TempDir folder;
    std::ofstream(folder.path / "typo.xml")
        << "<mujoco><worldbody>\n<bdoy pos=\"5 0 0\"><geom size=\"2\"/></bdoy>\n"
           "<body eular=\"0 0 90\" pos=\"1 0 0\">\n<geom type=\"box\" size=\"1 1 1\" poss=\"1 0 0\"/>\n"
           "<joint/><inertial pos=\"0 0 0\" mass=\"1\"/><site/></body>\n</worldbody></mujoco>";
    const Result<ImportResult> imported = import_mjcf((folder.path / "typo.xml").string());
    ASSERT_TRUE(imported.has_value()) << imported.error().to_string();
    EXPECT_EQ(imported->primitives.size(), 1u);
    ASSERT_EQ(imported->warnings.size(), 3u);
    EXPECT_NE(imported->warnings[0].find("typo.xml:2: unknown element <bdoy> in a body skipped"), std::string::npos)
        << imported->warnings[0];
    EXPECT_NE(imported->warnings[1].find("typo.xml:3: unknown attribute 'eular' of <body> ignored"), std::string::npos)
        << imported->warnings[1];
    EXPECT_NE(imported->warnings[2].find("typo.xml:4: unknown attribute 'poss' of <geom> ignored"), std::string::npos)
        << imported->warnings[2];
}

TEST(Mjcf, AFileIsIncludedOnceAsInMuJoCo) {
    // 17 small files, each including the next one twice: expanded every time, the 2^16 copies took minutes and
    // gigabytes. MuJoCo refuses the second include of a file; so does the importer, at once, naming both places.
    TempDir folder;
    for (int i = 0; i < 16; ++i)
        std::ofstream(folder.path / ("L" + std::to_string(i) + ".xml"))
            << "<mujoco>\n<include file=\"L" << i + 1 << ".xml\"/>\n<include file=\"L" << i + 1 << ".xml\"/>\n</mujoco>";
    std::ofstream(folder.path / "L16.xml") << "<mujoco><worldbody><geom size=\"1\"/></worldbody></mujoco>";
    const Result<ImportResult> imported = import_mjcf((folder.path / "L0.xml").string());
    ASSERT_FALSE(imported.has_value());
    // Depth first: the first file read twice is the last one, from L15.xml's second line of includes.
    EXPECT_EQ(fs::path(imported.error().file).filename(), "L15.xml");
    EXPECT_EQ(imported.error().line, 3);
    EXPECT_NE(imported.error().message.find("'L16.xml' is included a second time (first at "), std::string::npos)
        << imported.error().to_string();
    // Once is fine, from the defaults' pass and the bodies' pass alike.
    std::ofstream(folder.path / "once.xml")
        << "<mujoco><include file=\"L16.xml\"/><worldbody><geom size=\"2\"/></worldbody></mujoco>";
    const Result<ImportResult> once = import_mjcf((folder.path / "once.xml").string());
    ASSERT_TRUE(once.has_value()) << once.error().to_string();
    EXPECT_EQ(once->primitives.size(), 2u);
}

}  // namespace
}  // namespace hbvh
