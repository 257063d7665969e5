// SPDX-License-Identifier: MIT
// Regressions for importer bugs found by the fuzzers (fuzz/) and by the bad-input survey (docs/bad-input.md):
// each input once crashed, hung or produced primitives that hbvh's own XML reader refuses.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "hbvh/io/mesh_import.hpp"
#include "hbvh/io/mjcf.hpp"
#include "hbvh/io/urdf.hpp"
#include "hbvh/io/xml.hpp"

namespace hbvh {
namespace {

namespace fs = std::filesystem;

/// A fresh folder for one test, removed at the end.
class ScratchFolder {
public:
    explicit ScratchFolder(const std::string& name) : path_(fs::temp_directory_path() / ("hbvh_regression_" + name)) {
        fs::remove_all(path_);
        fs::create_directories(path_);
    }
    ~ScratchFolder() {
        std::error_code ignored;
        fs::remove_all(path_, ignored);
    }
    std::string write(const std::string& name, const std::string& content) const {
        const fs::path file = path_ / name;
        std::ofstream(file, std::ios::binary) << content;
        return file.string();
    }

private:
    fs::path path_;
};

/// Everything imported must read back through the survey format (what `hbvh convert` then `hbvh build` do).
void expect_round_trip(const ImportResult& imported) {
    const Result<XmlModel> again = read_xml_string(write_primitives_xml(imported.primitives), "round trip");
    ASSERT_TRUE(again.has_value()) << again.error().to_string();
    EXPECT_EQ(again->primitives.size(), imported.primitives.size());
}

// assimp 5.2 looped and allocated for minutes on a PLY header declaring far more elements than the file holds.
TEST(ImportRegressions, PlyHeaderCountsBeyondTheFileAreRefused) {
    const ScratchFolder folder("ply_header");
    const std::string path = folder.write(
        "huge.ply", "ply\nformat ascii 1.0\nelement vertex 99999999999\nproperty float x\nend_header\n");
    const Result<ImportResult> imported = import_mesh(path);
    ASSERT_FALSE(imported.has_value());
    EXPECT_EQ(imported.error().file, path);
    EXPECT_EQ(imported.error().line, 5);
    EXPECT_NE(imported.error().message.find("PLY header declares"), std::string::npos) << imported.error().message;

    // Binary, counts that fit: still read (the check counts at least one byte per property).
    const std::string binary_header = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
                                      "property float y\nproperty float z\nelement face 1\n"
                                      "property list uchar int vertex_indices\nend_header\n";
    std::string body(9 * sizeof(float), '\0');
    const float corners[9] = {0, 0, 0, 1, 0, 0, 0, 1, 1};
    std::memcpy(body.data(), corners, sizeof corners);
    body += std::string(1, '\3');
    const std::int32_t indices[3] = {0, 1, 2};
    body.append(reinterpret_cast<const char*>(indices), sizeof indices);
    MeshImportOptions per_mesh;
    per_mesh.one_primitive_per_mesh = true;
    const Result<ImportResult> triangle = import_mesh(folder.write("triangle.ply", binary_header + body), per_mesh);
    ASSERT_TRUE(triangle.has_value()) << triangle.error().to_string();
    EXPECT_EQ(triangle->primitives.size(), 1u);
    // One byte short of the smallest possible body: refused.
    const std::string short_header = "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty uchar x\n"
                                     "property uchar y\nend_header\n";
    EXPECT_FALSE(import_mesh(folder.write("short.ply", short_header + std::string(7, '\1'))).has_value());
}

// assimp 5.2 looped forever looking for the end of a PLY header that has none (found by fuzz_ply).
TEST(ImportRegressions, PlyHeaderWithoutEndIsRefused) {
    const ScratchFolder folder("ply_no_end");
    const std::string path = folder.write("open.ply", "ply\nformat ascii 1.0\ncomment a tetrahedron\n"
                                                      "elemen int vertex_indir7s\ne\n1 0 ader\n0 0 0\n1 0 0\n"
                                                      "0 1 0\n0 0 1 z\nelement face 4\nprope3\n3 1 2 3\n");
    const Result<ImportResult> imported = import_mesh(path);
    ASSERT_FALSE(imported.has_value());
    EXPECT_NE(imported.error().message.find("PLY header"), std::string::npos) << imported.error().message;
}

// A binary PLY whose magic line is "ply" plus garbage and whose header never ends: assimp 5.2 read out of bounds
// (SEGV, found by fuzz_ply). The header check now applies to every file starting with "ply", as assimp's does.
TEST(ImportRegressions, PlyWithGarbageAfterTheMagicIsChecked) {
    const ScratchFolder folder("ply_magic");
    const std::string bytes(
        "ply\xff\xff\xff\xff\nformat binary_little_endian 1.0\nelement vertex 3\npr\x00\x00\x00\x00\x00\x00\x00\x00\x00o"
        "perty float x\nproperty float y\nproperty float !z\nelement face 2\nproperty list uchar "
        "int vertformat binary_little_endian 1.0\x00\x00\x00\x00\x00\x80?\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x80?"
        "\x00\x00\x00\x00\x03\x00\x00\x00\x00\x01\x00\x00\x00\x02\x00\x00\x00",
        232);
    const Result<ImportResult> imported = import_mesh(folder.write("crash.ply", bytes));
    ASSERT_FALSE(imported.has_value());
    EXPECT_NE(imported.error().message.find("PLY header"), std::string::npos) << imported.error().message;
}

// assimp 5.2 also takes "plY" and a magic after leading line breaks as PLY, and hung on such files without
// end_header (found by fuzz_ply): the header check matches the magic as loosely, then wants a proper "ply" line.
TEST(ImportRegressions, PlyMagicInAnyCaseOrAfterLineBreaksIsChecked) {
    const ScratchFolder folder("ply_loose_magic");
    const std::vector<std::string> prefixes{"plY",   "PLY", "\nply", "\r\n\nply",
                                            "\tply", std::string("\0\0\0\5\nply", 8)};
    for (const std::string& prefix : prefixes) {
        SCOPED_TRACE(prefix);
        const std::string path = folder.write(
            "open.ply", prefix + "\nformat binary_little_endply\nformat ascii 1.0\nelement vertex 4\npria");
        const Result<ImportResult> imported = import_mesh(path);
        ASSERT_FALSE(imported.has_value());
        EXPECT_EQ(imported.error().line, 1);
        EXPECT_NE(imported.error().message.find("first line must be exactly \"ply\""), std::string::npos)
            << imported.error().message;
    }
}

// The header's grammar is checked line by line, so that assimp only ever sees a well-formed header: a vertical
// tab after end_header hung it (fuzz_ply), and unknown keywords or malformed lines are refused with the line.
TEST(ImportRegressions, PlyHeaderGrammarIsChecked) {
    const ScratchFolder folder("ply_grammar");
    const std::string start = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n";
    const std::pair<std::string, std::string> cases[] = {
        {start + "end_header\v0 0 0\n", "a control or non-ASCII byte outside a comment"},
        {start + "end_header 0 0 0\n", "end_header must stand alone"},
        {start + "elemfo float y\nend_header\n0\n", "unknown keyword \"elemfo\""},
        {start + "property floot y\nend_header\n0 0\n", "expected \"property TYPE NAME\""},
        {start + "element face -1\nend_header\n0\n", "expected \"element NAME COUNT\""},
        {start + "element 2222222222face 1\nend_header\n0\n", "expected \"element NAME COUNT\""},
        {start + "property float 9y\nend_header\n0 0\n", "expected \"property TYPE NAME\""},
        {"ply\nproperty float x\nend_header\n0\n", "the second line must be"},
        {"ply\ncomment first\nformat ascii 1.0\nend_header\n", "the second line must be"},
        {"ply\nformat ascii 1.0\nproperty float x\nend_header\n0\n", "a property before any element"},
    };
    for (const auto& [text, problem] : cases) {
        SCOPED_TRACE(text);
        const Result<ImportResult> imported = import_mesh(folder.write("bad.ply", text));
        ASSERT_FALSE(imported.has_value());
        EXPECT_NE(imported.error().message.find(problem), std::string::npos) << imported.error().message;
        EXPECT_GT(imported.error().line, 0);
    }
    // What real writers put in a header still passes: comments with any bytes, obj_info, CRLF line ends, lists.
    const std::string good = "ply\r\nformat ascii 1.0\r\ncomment \xc3\xa9t\xc3\xa9 \x01\r\nobj_info made by hand\r\n"
                             "element vertex 4\r\nproperty float x\r\nproperty float y\r\nproperty float z\r\n"
                             "element face 1\r\nproperty list uchar int vertex_indices\r\nend_header\r\n"
                             "0 0 0\r\n1 0 0\r\n0 1 0\r\n0 0 1\r\n4 0 1 2 3\r\n";
    MeshImportOptions per_mesh;
    per_mesh.one_primitive_per_mesh = true;
    const Result<ImportResult> imported = import_mesh(folder.write("good.ply", good), per_mesh);
    ASSERT_TRUE(imported.has_value()) << imported.error().to_string();
    EXPECT_EQ(imported->primitives.size(), 1u);
}

// Coincident, collinear or coplanar collision pieces fitted zero-size volumes (a radius-0 sphere, a box of height
// 0), which `hbvh convert` wrote and every XML reader of hbvh then refused.
TEST(ImportRegressions, PointCollisionMeshesAreSkippedWithAWarningFlatOnesKept) {
    const ScratchFolder folder("degenerate_mesh");
    const std::string path = folder.write("pieces.obj",
                                          "o USP_point\nv 1 2 3\np 1\n"
                                          "o UCP_line\nv 0 0 0\nv 0 0 1\nv 0 0 2\nl 2 3 4\n"
                                          "o UBX_floor\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 5 6 7 8\n"
                                          "o UCX_point\nv 4 4 4\nv 4 4 4\np 9\np 10\n"
                                          "o UBX_crate\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 11 12 13\nf 11 12 14\n");
    const Result<ImportResult> imported = import_mesh(path);
    ASSERT_TRUE(imported.has_value()) << imported.error().to_string();
    // Whatever the fitters make of the line and the flat quad (rounding may leave them a tiny positive size), every
    // primitive that comes out must read back.
    expect_round_trip(*imported);
    auto has_primitive = [&](const std::string& name) {
        return std::any_of(imported->primitives.begin(), imported->primitives.end(),
                           [&](const Primitive& p) { return p.name == name; });
    };
    EXPECT_TRUE(has_primitive("UBX_crate"));
    // A line and a flat quad are shapes (a capsule of radius 0, a box of zero height), kept as URDF's rods and
    // plates are; until 2026-12-08 they were skipped with the points, unless rounding left them a tiny size.
    EXPECT_TRUE(has_primitive("UCP_line"));
    EXPECT_TRUE(has_primitive("UBX_floor"));
    // A single point and two coincident points have size exactly zero: skipped, each with a warning.
    for (const char* name : {"USP_point", "UCX_point"}) {
        EXPECT_FALSE(has_primitive(name)) << name;
        const bool warned = std::any_of(imported->warnings.begin(), imported->warnings.end(), [&](const std::string& w) {
            return w.find(name) != std::string::npos && w.find("skipped") != std::string::npos;
        });
        EXPECT_TRUE(warned) << name;
    }
}

// A plain mesh read one primitive per node (mesh-nodes): an axis-aligned floor fitted a box of zero height and was
// dropped with a warning, so a file of only a floor was refused (an asset-pipeline review, 2026-12-08).
TEST(ImportRegressions, AFlatRenderMeshIsAFlatBoxOnePrimitivePerNode) {
    const ScratchFolder folder("flat_render_mesh");
    const std::string path = folder.write("floor.obj", "o floor\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3 4\n");
    MeshImportOptions options;
    options.one_primitive_per_mesh = true;
    const Result<ImportResult> imported = import_mesh(path, options);
    ASSERT_TRUE(imported.has_value()) << imported.error().to_string();
    ASSERT_EQ(imported->primitives.size(), 1u);
    const Aabb box = world_aabb(imported->primitives.front().volume);
    EXPECT_NEAR(box.min.x(), -1.0, 1e-6);
    EXPECT_NEAR(box.max.y(), 1.0, 1e-6);
    EXPECT_NEAR(box.max.z() - box.min.z(), 0.0, 1e-5);  // grown by the vertices' single-precision rounding
    expect_round_trip(*imported);
}

// Sizes and positions near the limit of double were accepted although the volume could not be written (a half
// size of 1e308 is a full size of inf), so `hbvh convert` wrote files hbvh could not read. Found with the fuzz
// targets' round-trip property.
// urdfdom 3 accepts a joint whose parent and child are the same link when another link is the root; composing
// that link's frame recursed forever (stack overflow, found by fuzz_urdf).
TEST(ImportRegressions, UrdfLinkThatIsItsOwnParentIsRefused) {
    const ScratchFolder folder("urdf_cycle");
    const std::string path = folder.write(
        "robot.urdf",
        "<robot name=\"r\">\n<link name=\"base\"/>\n"
        "<link name=\"lower\"><collision><geometry><sphere radius=\"1\"/></geometry></collision></link>\n"
        "<joint name=\"elbow\" type=\"fixed\"><parent link=\"lower\"/><child link=\"lower\"/></joint>\n"
        "</robot>\n");
    const Result<ImportResult> imported = import_urdf(path);
    ASSERT_FALSE(imported.has_value());
    EXPECT_EQ(imported.error().line, 3);
    EXPECT_NE(imported.error().message.find("its own ancestor"), std::string::npos) << imported.error().message;
}

TEST(ImportRegressions, OverflowingGeometryIsRefused) {
    const ScratchFolder folder("overflow");
    for (const std::string geom : {"<geom type=\"box\" size=\"1e308 1 1\"/>",
                                   "<geom type=\"capsule\" fromto=\"-1e308 0 0 1e308 0 0\" size=\"1\"/>",
                                   "<body pos=\"1e308 0 0\"><geom pos=\"1e308 0 0\" size=\"1\"/></body>"}) {
        const Result<ImportResult> imported =
            import_mjcf(folder.write("model.xml", "<mujoco>\n<worldbody>\n" + geom + "\n</worldbody>\n</mujoco>\n"));
        ASSERT_FALSE(imported.has_value()) << geom;
        EXPECT_EQ(imported.error().line, 3) << geom;
        EXPECT_NE(imported.error().message.find("overflows double"), std::string::npos) << imported.error().message;
    }
    // Still fine a little below the limit.
    const Result<ImportResult> large =
        import_mjcf(folder.write("large.xml", "<mujoco><worldbody><geom type=\"box\" size=\"1e307 1 1\"/></worldbody></mujoco>"));
    ASSERT_TRUE(large.has_value()) << large.error().to_string();
    expect_round_trip(*large);

    const Result<ImportResult> robot = import_urdf(folder.write(
        "robot.urdf", "<robot name=\"r\">\n<link name=\"a\"/>\n<link name=\"b\">\n"
                      "<collision><origin xyz=\"1e308 0 0\"/><geometry><sphere radius=\"1\"/></geometry></collision>\n"
                      "</link>\n<joint name=\"j\" type=\"fixed\"><parent link=\"a\"/><child link=\"b\"/>"
                      "<origin xyz=\"1e308 0 0\"/></joint>\n</robot>\n"));
    ASSERT_FALSE(robot.has_value());
    EXPECT_EQ(robot.error().line, 4);
    EXPECT_NE(robot.error().message.find("overflows double"), std::string::npos) << robot.error().message;
}

// <include file="/dev/zero"> read forever (and /dev/stdin waited for input): included files come from the model,
// so only regular files are followed.
TEST(ImportRegressions, MjcfIncludeOfADeviceOrFolderIsRefused) {
    const ScratchFolder folder("mjcf_device");
    for (const std::string target : {"/dev/zero", "."}) {
        const std::string path = folder.write(
            "model.xml", "<mujoco>\n  <include file=\"" + target + "\"/>\n  <worldbody><geom size=\"1\"/></worldbody>\n</mujoco>\n");
        const Result<ImportResult> imported = import_mjcf(path);
        ASSERT_FALSE(imported.has_value()) << target;
        EXPECT_EQ(imported.error().line, 2) << target;
        EXPECT_NE(imported.error().message.find("not a regular file"), std::string::npos) << imported.error().message;
    }
}

}  // namespace
}  // namespace hbvh
