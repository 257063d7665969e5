// SPDX-License-Identifier: MIT
// read_model_file and read_model_bytes: every input format through one call, a stored hierarchy kept from survey
// XML and .hbvh (whatever the name says, the bytes decide), MJCF under .xml, the importers' empty results refused
// with their reasons, and the refusals the CLI and the Python module rely on.
#include "hbvh/io/model_file.hpp"

#include <algorithm>
#include <fstream>
#include <iterator>
#include <sstream>
#include <thread>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include "hbvh/io/file.hpp"
#include "hbvh/io/xml.hpp"
#include "hbvh/tree/binary_format.hpp"
#include "hbvh/tree/validate.hpp"
#include "io/import_test_support.hpp"
#include "io/sample_hierarchy.hpp"

namespace hbvh {
namespace {

namespace fs = std::filesystem;

class ModelFileTest : public ::testing::Test {
protected:
    void SetUp() override {
        folder_ = fs::temp_directory_path() / ("hbvh_model_file_" + std::to_string(::getpid()));
        fs::create_directories(folder_);
    }
    void TearDown() override { fs::remove_all(folder_); }
    std::string path(const std::string& name) const { return (folder_ / name).string(); }
    void write(const std::string& name, const std::string& content) const {
        std::ofstream(folder_ / name, std::ios::binary) << content;
    }
    fs::path folder_;
};

/// Same primitives (kinds, numbers within the XML's decimal rounding, names) and, with a hierarchy, same shape.
void expect_same(const ModelFile& read, const Bvh& written) {
    ASSERT_EQ(read.primitives.size(), written.primitives.size());
    for (std::size_t i = 0; i < written.primitives.size(); ++i) {
        EXPECT_EQ(test::compare_volumes(read.primitives[i].volume, written.primitives[i].volume, 1e-12), "") << i;
        EXPECT_EQ(read.primitives[i].name, written.primitives[i].name) << i;
    }
    ASSERT_TRUE(read.hierarchy.has_value());
    ASSERT_EQ(read.hierarchy->nodes.size(), written.nodes.size());
    for (std::size_t i = 0; i < written.nodes.size(); ++i) {
        EXPECT_EQ(read.hierarchy->nodes[i].child_count, written.nodes[i].child_count) << i;
        EXPECT_EQ(read.hierarchy->nodes[i].first_child, written.nodes[i].first_child) << i;
    }
}

TEST_F(ModelFileTest, StoredHierarchiesComeBackFromXmlAndBinaryWhateverTheName) {
    const Bvh tree = test::sample_hierarchy();
    write("tree.xml", write_xml(tree));
    ASSERT_TRUE(write_binary_file(path("tree.hbvh"), tree));
    const std::string binary = write_binary(tree);
    write("binary_named.xml", binary);

    // Survey XML lists a hierarchy's primitives in its leaves' order: what the XML reader itself gives.
    const Result<ModelFile> xml = read_model_file(path("tree.xml"));
    ASSERT_TRUE(xml.has_value()) << xml.error().to_string();
    const Result<XmlModel> direct = read_xml_file(path("tree.xml"));
    ASSERT_TRUE(direct.has_value() && direct->hierarchy.has_value());
    expect_same(*xml, *direct->hierarchy);
    EXPECT_EQ(xml->node_lines, direct->node_lines);
    EXPECT_EQ(xml->node_lines.size(), tree.nodes.size());  // survey XML knows each node's line
    for (const std::string name : {"tree.hbvh", "binary_named.xml"}) {
        SCOPED_TRACE(name);
        const Result<ModelFile> read = read_model_file(path(name));
        ASSERT_TRUE(read.has_value()) << read.error().to_string();
        expect_same(*read, tree);
        EXPECT_TRUE(read->node_lines.empty());
    }
    // Bytes in memory, as from an archive or standard input.
    const Result<ModelFile> from_bytes = read_model_bytes(binary, "asset");
    ASSERT_TRUE(from_bytes.has_value()) << from_bytes.error().to_string();
    expect_same(*from_bytes, tree);
    const Result<ModelFile> from_text = read_model_bytes(write_xml(tree), "asset");
    ASSERT_TRUE(from_text.has_value()) << from_text.error().to_string();
    expect_same(*from_text, *direct->hierarchy);
    // A primitive set has no hierarchy.
    write("set.xml", write_primitives_xml(tree.primitives));
    const Result<ModelFile> set = read_model_file(path("set.xml"));
    ASSERT_TRUE(set.has_value()) << set.error().to_string();
    EXPECT_EQ(set->primitives.size(), tree.primitives.size());
    EXPECT_FALSE(set->hierarchy.has_value());
    // Broken bytes are the binary reader's error, naming the source.
    const Result<ModelFile> cut = read_model_bytes(binary.substr(0, binary.size() - 3), "asset");
    ASSERT_FALSE(cut.has_value());
    EXPECT_EQ(cut.error().file, "asset");
    EXPECT_NE(cut.error().message.find("truncated"), std::string::npos) << cut.error().message;
}

TEST_F(ModelFileTest, ANameThatTellsNothingIsReadByItsBytes) {
    const Bvh tree = test::sample_hierarchy();
    const std::string binary = write_binary(tree);
    write("tree", binary);
    write("tree.bin", binary);
    write("set", write_primitives_xml(tree.primitives));
    for (const std::string name : {"tree", "tree.bin"}) {
        const Result<ModelFile> read = read_model_file(path(name));
        ASSERT_TRUE(read.has_value()) << name << ": " << read.error().to_string();
        expect_same(*read, tree);
    }
    const Result<ModelFile> set = read_model_file(path("set"));
    ASSERT_TRUE(set.has_value()) << set.error().to_string();
    EXPECT_EQ(set->primitives.size(), tree.primitives.size());
    const Result<ModelFile> named = read_model_file(path("tree"), "hbvh");
    ASSERT_TRUE(named.has_value()) << named.error().to_string();
    expect_same(*named, tree);
    const Result<ModelFile> not_binary = read_model_file(path("set"), "hbvh");
    ASSERT_FALSE(not_binary.has_value());
    EXPECT_NE(not_binary.error().message.find("not an .hbvh file"), std::string::npos) << not_binary.error().message;

    // A pipe (as `hbvh stats <(...)` passes /dev/fd/N): one reader, the bytes decide.
    const fs::path fifo = folder_ / "pipe";
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    std::thread writer([&] { std::ofstream(fifo, std::ios::binary) << binary; });
    const Result<ModelFile> piped = read_model_file(fifo.string());
    // Should the reader never have opened the pipe, this open releases the writer, so the test fails, not hangs.
    const int release = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    writer.join();
    if (release >= 0) ::close(release);
    ASSERT_TRUE(piped.has_value()) << piped.error().to_string();
    expect_same(*piped, tree);

    // MJCF under a name that tells nothing is not guessed: the importers read paths (includes, meshes).
    write("robot", "<mujoco><worldbody><geom type='sphere' size='1'/></worldbody></mujoco>");
    const Result<ModelFile> mjcf = read_model_file(path("robot"));
    ASSERT_FALSE(mjcf.has_value());
    EXPECT_EQ(mjcf.error().file, path("robot"));
    EXPECT_NE(mjcf.error().message.find("--format"), std::string::npos) << mjcf.error().message;
    ASSERT_TRUE(read_model_file(path("robot"), "mjcf").has_value());
}

TEST_F(ModelFileTest, ImportersByExtensionRootAndFormat) {
    const fs::path data = test::test_data_dir();
    const std::string mjcf = (data / "mjcf_defaults.xml").string();
    const Result<ModelFile> by_root = read_model_file(mjcf);  // .xml with <mujoco>: MJCF
    ASSERT_TRUE(by_root.has_value()) << by_root.error().to_string();
    EXPECT_EQ(by_root->primitives.size(), 9u);
    EXPECT_FALSE(by_root->hierarchy.has_value());
    const Result<ModelFile> as_survey = read_model_file(mjcf, "xml");  // the format wins over the root
    ASSERT_FALSE(as_survey.has_value());
    EXPECT_EQ(as_survey.error().file, mjcf);
    const Result<ModelFile> urdf = read_model_file((data / "urdf_chain.urdf").string());
    ASSERT_TRUE(urdf.has_value()) << urdf.error().to_string();
    EXPECT_EQ(urdf->primitives.size(), 4u);
    const Result<ModelFile> forced = read_model_file(mjcf, "urdf");
    ASSERT_FALSE(forced.has_value());
    EXPECT_NE(forced.error().message.find("expected <robot>"), std::string::npos);
}

TEST_F(ModelFileTest, TheRootElementDecidesAnXmlFileNotATextSearch) {
    // A URDF saved as .xml is URDF: the same primitives as under its own name.
    const fs::path data = test::test_data_dir();
    std::ifstream urdf_file(data / "urdf_chain.urdf");
    const std::string urdf_text((std::istreambuf_iterator<char>(urdf_file)), std::istreambuf_iterator<char>());
    write("chain.xml", urdf_text);
    const Result<ModelFile> urdf = read_model_file(path("chain.xml"));
    ASSERT_TRUE(urdf.has_value()) << urdf.error().to_string();
    EXPECT_EQ(urdf->primitives.size(), 4u);
    // A survey hierarchy that mentions <mujoco> in a comment is still a survey hierarchy, its tree kept; after a
    // declaration, a comment and a DOCTYPE the root is found all the same.
    write("tree.xml", "<?xml version=\"1.0\"?>\n<!-- converted from a <mujoco> model -->\n<!DOCTYPE hierarchy>\n"
                      "<hierarchy>\n<volume type=\"sphere\" pos=\"0 0 0\" radius=\"2\">\n"
                      "  <volume type=\"sphere\" pos=\"0 0 0\" radius=\"1\"/>\n"
                      "  <volume type=\"sphere\" pos=\"0.5 0 0\" radius=\"1\"/>\n</volume>\n</hierarchy>\n");
    const Result<ModelFile> tree = read_model_file(path("tree.xml"));
    ASSERT_TRUE(tree.has_value()) << tree.error().to_string();
    EXPECT_TRUE(tree->hierarchy.has_value());
    EXPECT_EQ(tree->primitives.size(), 2u);
}

TEST_F(ModelFileTest, RefusesDirectoriesUnknownFormatsAndFilesWithoutPrimitives) {
    fs::create_directories(folder_ / "scene.xml");
    const Result<ModelFile> directory = read_model_file(path("scene.xml"));
    ASSERT_FALSE(directory.has_value());
    EXPECT_EQ(directory.error().message, "is a directory, not a file");
    write("a.xml", "<hierarchy/>");
    const Result<ModelFile> unknown = read_model_file(path("a.xml"), "step");
    ASSERT_FALSE(unknown.has_value());
    EXPECT_NE(unknown.error().message.find("unknown input format 'step'"), std::string::npos);
    // Four skipped geoms: the message names the first three and counts the rest.
    write("meshes.xml", "<mujoco><worldbody><geom name='a' type='mesh' mesh='m'/><geom name='b' type='mesh' mesh='m'/>"
                        "<geom name='c' type='mesh' mesh='m'/><geom name='d' type='mesh' mesh='m'/></worldbody></mujoco>");
    const Result<ModelFile> empty = read_model_file(path("meshes.xml"));
    ASSERT_FALSE(empty.has_value());
    EXPECT_EQ(empty.error().message.rfind("the file holds no collision primitives: ", 0), 0u) << empty.error().message;
    EXPECT_NE(empty.error().message.find("; and 1 more"), std::string::npos) << empty.error().message;
}

TEST_F(ModelFileTest, ChecksRefuseBadPrimitivesAndBrokenTreesNamingTheSource) {
    ModelFile model;
    model.primitives = {{Sphere{Vec3(0, 0, 0), 1}, "a"}, {Sphere{Vec3(1, 0, 0), -2}, "b"}};
    const Status negative = check_model_file(model, "m.xml");
    ASSERT_FALSE(negative.has_value());
    EXPECT_EQ(negative.error().file, "m.xml");
    EXPECT_NE(negative.error().message.find("primitive 1 ('b')"), std::string::npos) << negative.error().message;

    model.primitives[1].volume = Sphere{Vec3(1, 0, 0), 2};
    EXPECT_TRUE(check_model_file(model, "m.xml").has_value());
    Bvh tree = test::sample_hierarchy();
    tree.nodes[0].first_child = static_cast<std::uint32_t>(tree.nodes.size());  // children past the end
    model.primitives = tree.primitives;
    model.hierarchy = tree;
    const Status broken = check_model_file(model, "m.xml");
    ASSERT_FALSE(broken.has_value());
    EXPECT_EQ(broken.error().file, "m.xml");
}

TEST_F(ModelFileTest, EnclosingHierarchyNamesTheFirstBadVolumeOrRefitsOnlyTheBadOnes) {
    // The appendix's tree with its volumes as printed: eight do not enclose their primitives (docs/bad-input.md).
    const std::string file = (fs::path(HBVH_SOURCE_DIR) / "tests/io/data/survey_appendix_b_repaired.xml").string();
    const Result<ModelFile> read = read_model_file(file);
    ASSERT_TRUE(read.has_value()) << read.error().to_string();
    ASSERT_TRUE(check_model_file(*read, file).has_value());
    const Bvh& stored = *read->hierarchy;
    const std::vector<ContainmentViolation> violations = containment_violations(stored);
    ASSERT_EQ(violations.size(), 8u);

    const Result<Bvh> refused = enclosing_hierarchy(stored, read->node_lines, file, false, "--refit");
    ASSERT_FALSE(refused.has_value());
    EXPECT_EQ(refused.error().file, file);
    EXPECT_EQ(refused.error().line, read->node_lines[violations.front().node]);
    EXPECT_EQ(refused.error().message, describe_violation(stored, violations.front()) + " (and 7 more volumes); --refit refits them");

    std::size_t refitted = 0;
    const Result<Bvh> repaired = enclosing_hierarchy(stored, read->node_lines, file, true, "--refit", &refitted);
    ASSERT_TRUE(repaired.has_value()) << repaired.error().to_string();
    EXPECT_TRUE(containment_violations(*repaired).empty());
    // The same tree, and only volumes that were wrong changed.
    ASSERT_EQ(repaired->nodes.size(), stored.nodes.size());
    std::size_t changed = 0;
    for (std::size_t i = 0; i < stored.nodes.size(); ++i) {
        EXPECT_EQ(repaired->nodes[i].first_child, stored.nodes[i].first_child);
        EXPECT_EQ(repaired->nodes[i].child_count, stored.nodes[i].child_count);
        EXPECT_EQ(type_of(repaired->nodes[i].volume), type_of(stored.nodes[i].volume)) << i;
        if (test::compare_volumes(repaired->nodes[i].volume, stored.nodes[i].volume, 0.0).empty()) continue;
        ++changed;
        const bool was_bad = std::any_of(violations.begin(), violations.end(),
                                         [&](const ContainmentViolation& v) { return v.node == i; });
        EXPECT_TRUE(was_bad) << "node " << i << " enclosed its primitives and was refitted anyway";
    }
    EXPECT_EQ(changed, refitted);
    EXPECT_GE(refitted, 1u);

    // A sound tree comes back as it is.
    const Bvh sound = *repaired;
    std::size_t none = 99;
    const Result<Bvh> kept = enclosing_hierarchy(sound, {}, "x.hbvh", false, "--refit", &none);
    ASSERT_TRUE(kept.has_value());
    EXPECT_EQ(none, 0u);
    EXPECT_EQ(write_binary(*kept), write_binary(sound));
}

}  // namespace
}  // namespace hbvh
