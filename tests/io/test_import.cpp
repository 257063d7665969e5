// SPDX-License-Identifier: MIT
// import_primitives: dispatch by extension and root element.
#include "hbvh/io/import.hpp"

#include <fstream>

#include <gtest/gtest.h>

#include "io/import_test_support.hpp"

namespace hbvh {
namespace {

namespace fs = std::filesystem;

TEST(Import, DispatchesByExtensionAndRoot) {
    const fs::path data = test::test_data_dir();
    const Result<ImportResult> mjcf = import_primitives((data / "mjcf_defaults.xml").string());
    ASSERT_TRUE(mjcf.has_value()) << mjcf.error().to_string();
    EXPECT_EQ(mjcf->primitives.size(), 9u);
    const Result<ImportResult> urdf = import_primitives((data / "urdf_chain.urdf").string());
    ASSERT_TRUE(urdf.has_value()) << urdf.error().to_string();
    EXPECT_EQ(urdf->primitives.size(), 4u);
    const Result<ImportResult> mesh = import_primitives((data / "mesh_collision_convention.obj").string());
    ASSERT_TRUE(mesh.has_value()) << mesh.error().to_string();
    EXPECT_EQ(mesh->primitives.size(), 4u);
    // An explicit format wins over the extension.
    const Result<ImportResult> forced = import_primitives((data / "mjcf_defaults.xml").string(), ImportFormat::urdf);
    ASSERT_FALSE(forced.has_value());
    EXPECT_NE(forced.error().message.find("expected <robot>"), std::string::npos);
}

TEST(Import, UnknownExtensionAndOtherXmlAreErrors) {
    const fs::path folder = fs::temp_directory_path() / "hbvh_import_dispatch";
    fs::create_directories(folder);
    std::ofstream(folder / "model.step") << "ISO-10303-21;";
    const Result<ImportResult> step = import_primitives((folder / "model.step").string());
    ASSERT_FALSE(step.has_value());
    EXPECT_NE(step.error().message.find("unknown file type"), std::string::npos);
    std::ofstream(folder / "survey.xml") << "<hbvh/>";
    const Result<ImportResult> survey = import_primitives((folder / "survey.xml").string());
    ASSERT_FALSE(survey.has_value());
    EXPECT_NE(survey.error().message.find("survey-format"), std::string::npos);
    fs::remove_all(folder);
}

}  // namespace
}  // namespace hbvh
