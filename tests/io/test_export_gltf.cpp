// SPDX-License-Identifier: MIT
// export_gltf(): structure, embedded buffer contents, and the Khronos validator's verdict.
#include <gtest/gtest.h>
#include <unistd.h>

#include <bit>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "hbvh/builders/build.hpp"
#include "hbvh/io/export_gltf.hpp"
#include "hbvh/io/level_view.hpp"
#include "hbvh/scene/generate.hpp"
#include "io/sample_hierarchy.hpp"

namespace hbvh {
namespace {

using nlohmann::json;

std::vector<std::uint8_t> decode_base64(const std::string& text) {
    std::vector<std::uint8_t> out;
    std::uint32_t bits = 0;
    int bit_count = 0;
    for (char c : text) {
        int value = -1;
        if (c >= 'A' && c <= 'Z') value = c - 'A';
        else if (c >= 'a' && c <= 'z') value = c - 'a' + 26;
        else if (c >= '0' && c <= '9') value = c - '0' + 52;
        else if (c == '+') value = 62;
        else if (c == '/') value = 63;
        if (value < 0) continue;
        bits = (bits << 6) | static_cast<std::uint32_t>(value);
        bit_count += 6;
        if (bit_count >= 8) {
            bit_count -= 8;
            out.push_back(static_cast<std::uint8_t>(bits >> bit_count));
        }
    }
    return out;
}

float read_float(const std::vector<std::uint8_t>& bytes, std::size_t offset) {
    std::uint32_t word = 0;
    for (int k = 0; k < 4; ++k) word |= std::uint32_t{bytes.at(offset + k)} << (8 * k);
    return std::bit_cast<float>(word);
}

TEST(ExportGltf, OneSceneNodePerLevelWithEveryShownBv) {
    const Bvh bvh = test::sample_hierarchy();
    const json gltf = json::parse(export_gltf(bvh).value());
    EXPECT_EQ(gltf["asset"]["version"], "2.0");
    const std::vector<LevelView> views = level_views(bvh);
    const json& roots = gltf["scenes"][0]["nodes"];
    ASSERT_EQ(roots.size(), views.size());
    for (std::size_t d = 0; d < views.size(); ++d) {
        const json& level = gltf["nodes"][roots[d].get<std::size_t>()];
        EXPECT_EQ(level["name"], "level " + std::to_string(d));
        EXPECT_EQ(level["children"].size(), views[d].nodes.size() + views[d].carried.size());
        EXPECT_EQ(level["extras"]["depth"], d);
        EXPECT_DOUBLE_EQ(level["extras"]["cost"].get<double>(), views[d].cost);
        // Side by side: later levels further along +x.
        if (d > 0) {
            EXPECT_GT(level["translation"][0].get<double>(), 0.0);
        }
    }
    for (const json& material : gltf["materials"]) {
        EXPECT_EQ(material["alphaMode"], "BLEND");
        EXPECT_LT(material["pbrMetallicRoughness"]["baseColorFactor"][3].get<double>(), 1.0);
    }
    // A level colour per level, plus one for carried leaves.
    EXPECT_EQ(gltf["materials"].size(), views.size() + 1);
}

TEST(ExportGltf, EmbeddedBufferHoldsTheMeshes) {
    const Bvh bvh = test::sample_hierarchy();
    const json gltf = json::parse(export_gltf(bvh).value());
    const std::string uri = gltf["buffers"][0]["uri"];
    const std::string prefix = "data:application/octet-stream;base64,";
    ASSERT_EQ(uri.rfind(prefix, 0), 0u);
    const std::vector<std::uint8_t> bytes = decode_base64(uri.substr(prefix.size()));
    ASSERT_EQ(bytes.size(), gltf["buffers"][0]["byteLength"].get<std::size_t>());

    // Every BV-bearing node: placed at the centre of the BV's world AABB, its POSITION accessor's bounds are that
    // AABB about the centre (as floats), and the stored positions agree with those bounds.
    for (const json& node : gltf["nodes"]) {
        if (!node.contains("mesh")) continue;
        const std::uint32_t index = node["extras"]["hbvh_node"];
        const json& primitive = gltf["meshes"][node["mesh"].get<std::size_t>()]["primitives"][0];
        const json& accessor = gltf["accessors"][primitive["attributes"]["POSITION"].get<std::size_t>()];
        const Aabb expected = world_aabb(bvh.nodes[index].volume);
        for (int k = 0; k < 3; ++k) {
            const double origin = node["translation"][k].get<double>();
            EXPECT_EQ(origin, expected.center()[k]);
            EXPECT_FLOAT_EQ(accessor["min"][k].get<float>(), static_cast<float>(expected.min[k] - origin));
            EXPECT_FLOAT_EQ(accessor["max"][k].get<float>(), static_cast<float>(expected.max[k] - origin));
        }
        const json& view = gltf["bufferViews"][accessor["bufferView"].get<std::size_t>()];
        const std::size_t stride = view["byteStride"];
        const std::size_t base = view["byteOffset"].get<std::size_t>() + accessor["byteOffset"].get<std::size_t>();
        for (std::size_t v = 0; v < accessor["count"].get<std::size_t>(); ++v)
            for (std::size_t k = 0; k < 3; ++k) {
                const float value = read_float(bytes, base + v * stride + 4 * k);
                EXPECT_GE(value, accessor["min"][k].get<float>());
                EXPECT_LE(value, accessor["max"][k].get<float>());
            }
    }
}

TEST(ExportGltf, EmptyHierarchyIsAValidEmptyAsset) {
    const json gltf = json::parse(export_gltf(Bvh{}).value());
    EXPECT_EQ(gltf["scenes"].size(), 1u);
    EXPECT_FALSE(gltf["scenes"][0].contains("nodes"));
}

/// Runs tools/validate_gltf.js (the Khronos validator) on `text`; skips when node or the package is absent.
void expect_valid_gltf(const std::string& text, const std::string& name) {
    const std::filesystem::path tools = std::filesystem::path(HBVH_SOURCE_DIR) / "tools";
    if (std::system("node --version > /dev/null 2>&1") != 0) GTEST_SKIP() << "node is not installed";
    if (!std::filesystem::exists(tools / "node_modules" / "gltf-validator" / "package.json"))
        GTEST_SKIP() << "gltf-validator is not installed (run `npm ci` in tools/)";
    // Per process: other checkouts may run the same test at the same time.
    const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / ("hbvh_gltf_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    const std::filesystem::path file = dir / (name + ".gltf");
    const std::filesystem::path log = dir / (name + ".log");
    std::ofstream(file, std::ios::binary) << text;
    const std::string command = "node '" + (tools / "validate_gltf.js").string() + "' '" + file.string() + "' > '" +
                                log.string() + "' 2>&1";
    const int status = std::system(command.c_str());
    std::ifstream in(log);
    const std::string report((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_EQ(status, 0) << report;
    std::filesystem::remove_all(dir);
}

TEST(ExportGltf, KhronosValidatorFindsNoErrors) {
    expect_valid_gltf(export_gltf(test::sample_hierarchy()).value(), "sample");
}

/// A root over every primitive, without fitters: the root is the union AABB of the leaves.
Bvh flat_tree(const std::vector<Primitive>& primitives) {
    TreeAssembler assembler(primitives);
    std::vector<std::uint32_t> leaves;
    Aabb box = Aabb::empty();
    for (std::uint32_t i = 0; i < primitives.size(); ++i) {
        leaves.push_back(assembler.add_leaf(i));
        box = box.merged(world_aabb(primitives[i].volume));
    }
    return std::move(assembler).finish(assembler.add_group(leaves, box));
}

TEST(ExportGltf, KhronosValidatorAcceptsAFlatTwoLevelScene) {
    // A root over a generated scene.
    SceneOptions options;
    options.count = 40;
    options.seed = 3;
    const std::vector<Primitive> primitives = generate_scene(options);
    const Bvh bvh = flat_tree(primitives);
    GltfOptions gltf_options;
    gltf_options.side_by_side = false;
    expect_valid_gltf(export_gltf(bvh, gltf_options).value(), "flat");
}

// Far from the origin, world coordinates as floats had kept 8 mm at 10^5 (a 4 cm box came out 3.9 cm wide):
// each mesh is now stored about its own centre, so a box keeps its size to float precision of the size.
TEST(ExportGltf, FarFromTheOriginEveryMeshKeepsItsSize) {
    std::vector<Primitive> primitives;
    for (int i = 0; i < 3; ++i)
        primitives.push_back({Aabb{Vec3(1e5 + 0.1 * i, 2e5, -3e5), Vec3(1e5 + 0.1 * i + 0.04, 2e5 + 0.035, -3e5 + 0.03)}, ""});
    const Bvh bvh = flat_tree(primitives);
    const json gltf = json::parse(export_gltf(bvh).value());
    for (const json& node : gltf["nodes"]) {
        if (!node.contains("mesh")) continue;
        const Aabb expected = world_aabb(bvh.nodes[node["extras"]["hbvh_node"].get<std::uint32_t>()].volume);
        const json& primitive = gltf["meshes"][node["mesh"].get<std::size_t>()]["primitives"][0];
        const json& accessor = gltf["accessors"][primitive["attributes"]["POSITION"].get<std::size_t>()];
        for (int k = 0; k < 3; ++k) {
            const double width = accessor["max"][k].get<double>() - accessor["min"][k].get<double>();
            const double true_width = expected.max[k] - expected.min[k];
            EXPECT_NEAR(width, true_width, 1e-6 * true_width) << "axis " << k;
        }
    }
    expect_valid_gltf(gltf.dump(), "far");
}

// A BV wider than a float holds has no mesh a viewer could draw: an Error, not a file with null bounds.
TEST(ExportGltf, RefusesABvWiderThanAFloatHolds) {
    const std::vector<Primitive> primitives{{Sphere{Vec3::Zero(), 1e39}, ""}};
    const Bvh bvh = build(primitives, Algorithm::two_level).value();
    const Result<std::string> gltf = export_gltf(bvh);
    ASSERT_FALSE(gltf.has_value());
    EXPECT_NE(gltf.error().message.find("wider than a glTF float holds"), std::string::npos) << gltf.error().message;
}

}  // namespace
}  // namespace hbvh
