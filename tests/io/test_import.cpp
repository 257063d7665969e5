// SPDX-License-Identifier: MIT
// import_primitives: dispatch by extension and root element.
#include "hbvh/io/import.hpp"

#include <fstream>
#include <vector>

#include <gtest/gtest.h>

#include "hbvh/io/xml.hpp"
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

TEST(Import, UnknownExtensionIsAnError) {
    const fs::path folder = fs::temp_directory_path() / "hbvh_import_dispatch";
    fs::create_directories(folder);
    std::ofstream(folder / "model.step") << "ISO-10303-21;";
    const Result<ImportResult> step = import_primitives((folder / "model.step").string());
    ASSERT_FALSE(step.has_value());
    EXPECT_NE(step.error().message.find("unknown file type"), std::string::npos);
    fs::remove_all(folder);
}

// Any other .xml is the survey format: its primitives come through, in file order.
TEST(Import, SurveyXmlGoesToTheSurveyReader) {
    const fs::path folder = fs::temp_directory_path() / "hbvh_import_survey";
    fs::create_directories(folder);
    std::vector<Primitive> primitives{{Sphere{Vec3(1, 2, 3), 0.5}, "ball"},
                                      {Obb{Vec3(0, 0, 1), Mat3::Identity(), Vec3(1, 2, 3)}, "crate"}};
    std::ofstream(folder / "survey.xml") << write_primitives_xml(primitives);
    const Result<ImportResult> survey = import_primitives((folder / "survey.xml").string());
    ASSERT_TRUE(survey.has_value()) << survey.error().to_string();
    ASSERT_EQ(survey->primitives.size(), 2u);
    EXPECT_EQ(test::compare_volumes(survey->primitives[0].volume, primitives[0].volume, 1e-12), "");
    EXPECT_EQ(test::compare_volumes(survey->primitives[1].volume, primitives[1].volume, 1e-12), "");
    std::ofstream(folder / "bad.xml") << "<unknown_root/>";
    const Result<ImportResult> bad = import_primitives((folder / "bad.xml").string());
    ASSERT_FALSE(bad.has_value());
    EXPECT_EQ(bad.error().file, (folder / "bad.xml").string());
    fs::remove_all(folder);
}

}  // namespace
}  // namespace hbvh
