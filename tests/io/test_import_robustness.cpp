// SPDX-License-Identifier: MIT
// Bad input never crashes: every attribute of the test models replaced by hostile values must give a value or an
// Error, and an Error must name the file.
#include <fstream>

#include <gtest/gtest.h>
#include <pugixml.hpp>

#include "hbvh/io/import.hpp"
#include "io/import_test_support.hpp"

namespace hbvh {
namespace {

namespace fs = std::filesystem;

void corrupt_every_attribute(const fs::path& model, const std::string& extension) {
    pugi::xml_document original;
    ASSERT_TRUE(original.load_file(model.c_str()));
    const fs::path folder = fs::temp_directory_path() / ("hbvh_robustness_" + model.stem().string());
    fs::create_directories(folder);
    const fs::path file = folder / ("corrupt" + extension);
    int runs = 0;
    for (const char* hostile : {"", "nan", "1e999", "-1", "0", "x y z", "1 2 3 4 5 6 7 8 9 10"}) {
        // Walk the attributes by index so each run changes exactly one of them in a fresh copy.
        for (int target = 0;; ++target) {
            pugi::xml_document copy;
            copy.reset(original);
            int index = 0;
            bool changed = false;
            for (pugi::xpath_node hit : copy.select_nodes("//*")) {
                for (pugi::xml_attribute attribute : hit.node().attributes()) {
                    if (index++ == target) {
                        attribute.set_value(hostile);
                        changed = true;
                    }
                }
            }
            if (!changed) break;
            ASSERT_TRUE(copy.save_file(file.c_str()));
            const Result<ImportResult> imported = import_primitives(file.string());
            if (!imported) {
                EXPECT_EQ(imported.error().file, file.string()) << imported.error().to_string();
            }
            ++runs;
        }
    }
    EXPECT_GT(runs, 20);
    fs::remove_all(folder);
}

TEST(ImportRobustness, HostileMjcfAttributes) {
    corrupt_every_attribute(test::test_data_dir() / "mjcf_defaults.xml", ".xml");
    corrupt_every_attribute(test::test_data_dir() / "mjcf_fromto.xml", ".xml");
}

TEST(ImportRobustness, HostileUrdfAttributes) { corrupt_every_attribute(test::test_data_dir() / "urdf_chain.urdf", ".urdf"); }

TEST(ImportRobustness, TruncatedFiles) {
    const fs::path folder = fs::temp_directory_path() / "hbvh_robustness_truncated";
    fs::create_directories(folder);
    for (const char* name : {"mjcf_orientations.xml", "urdf_chain.urdf", "mesh_collision_convention.obj",
                             "mesh_collision_convention.gltf"}) {
        std::ifstream stream(test::test_data_dir() / name, std::ios::binary);
        const std::string text((std::istreambuf_iterator<char>(stream)), std::istreambuf_iterator<char>());
        const fs::path file = folder / name;
        for (std::size_t cut = 0; cut < text.size(); cut += std::max<std::size_t>(1, text.size() / 40)) {
            std::ofstream(file, std::ios::binary) << text.substr(0, cut);
            const Result<ImportResult> imported = import_primitives(file.string());
            if (!imported) {
                EXPECT_EQ(imported.error().file, file.string()) << imported.error().to_string();
            }
        }
    }
    fs::remove_all(folder);
}

}  // namespace
}  // namespace hbvh
