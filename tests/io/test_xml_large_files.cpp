// SPDX-License-Identifier: MIT
// The XML reader's lines and first error where its fast path could get them wrong: it counts lines on a table
// made before pugixml's in-place parse (which turns newlines inside attribute values into spaces and "\r\n" into
// "\n"), and it converts the volumes of a large file on all cores. The expected lines and errors are those of a
// plain one-pass reading of the text, worked out here from how the text was put together.
#include "hbvh/io/xml.hpp"

#include <gtest/gtest.h>
#include <pugixml.hpp>
#include <tbb/task_arena.h>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace hbvh {
namespace {

/// A flat file of spheres, volume i at index i, with the 1-based line of each volume's start tag. Every
/// seventh volume spreads its `pos` over three lines, so lines differ from volume indices by an uneven amount.
struct SphereFile {
    std::string text;
    std::vector<int> line_of_volume;
};

/// What replaces volume i's radius="1" to make it bad, by index.
using Faults = std::map<std::size_t, std::string>;

SphereFile sphere_file(std::size_t count, const Faults& faults = {}) {
    SphereFile file;
    file.text = "<?xml version=\"1.0\"?>\n<hierarchy>\n";
    int line = 3;
    for (std::size_t i = 0; i < count; ++i) {
        file.line_of_volume.push_back(line);
        const auto fault = faults.find(i);
        const std::string attributes = fault == faults.end() ? "radius=\"1\"" : fault->second;
        const bool spread = i % 7 == 3;
        file.text += "  <volume type=\"sphere\" pos=\"" + std::to_string(i) + (spread ? "\n 0\n 0\" " : " 0 0\" ") +
                     attributes + "/>\n";
        line += spread ? 3 : 1;
    }
    file.text += "</hierarchy>\n";
    return file;
}

Error read_error(const std::string& text) {
    Result<XmlModel> model = read_xml_string(text, "big.xml");
    EXPECT_FALSE(model.has_value());
    if (model) return Error("read without an error");
    return model.error();
}

// Well above the count from which the reader converts on all cores (16384), so that the work is split.
constexpr std::size_t large_count = 60000;

TEST(XmlLargeFiles, LineAfterMultiLineAttributeValues) {
    // The parse turns the newlines inside pos and orientation into spaces; lines still count them.
    const std::string text =
        "<hierarchy>\n"
        "  <volume type=\"obb\" pos=\"0\n0\n0\" width=\"1\" depth=\"1\" height=\"1\"\n"
        "    orientation=\"1 0 0\n  0 1 0\n  0 0 1\"/>\n"
        "  <volume type=\"sphere\" pos=\"0 0 0\" radius=\"-1\"/>\n"
        "</hierarchy>\n";
    const Error error = read_error(text);
    EXPECT_EQ(error.line, 8) << error.to_string();
    EXPECT_EQ(error.message, "attribute 'radius' must be >= 0, found -1");
}

TEST(XmlLargeFiles, NodeLinesAfterMultiLineAttributeValues) {
    const std::string text =
        "<hierarchy>\n"
        "<volume type=\"sphere\" pos=\"0\n0 0\" radius=\"9\">\n"
        "<volume type=\"sphere\" pos=\"1 0 0\" radius=\"1\"/>\n"
        "<volume type=\"sphere\" pos=\"-1\n0\n0\" radius=\"1\"/>\n"
        "<volume type=\"sphere\" pos=\"0 0 0\" radius=\"1\"/>\n"
        "</volume>\n"
        "</hierarchy>\n";
    const Result<XmlModel> model = read_xml_string(text, "nested.xml");
    ASSERT_TRUE(model) << model.error().to_string();
    ASSERT_TRUE(model->hierarchy);
    // Node 0 is the root, nodes 1-3 its leaves in document order.
    EXPECT_EQ(model->node_lines, (std::vector<int>{2, 4, 5, 8}));
}

TEST(XmlLargeFiles, LineOfStrayTextAfterRewrittenWhiteSpace) {
    const std::string sphere = "  <volume type=\"sphere\" pos=\"0 0 0\" radius=\"1\"/>";
    struct Case {
        const char* what;
        std::string text;
        int line;
    };
    const Case cases[] = {
        // Each "\r\n" is parsed into one '\n', which moves the text's first word forward in the buffer.
        {"after CRLF lines", "<hierarchy>\r\n" + sphere + "\r\n\r\n\r\nstray\r\n</hierarchy>\r\n", 5},
        // A lone '\r' is parsed into '\n' but ends no line: lines are counted by '\n' only.
        {"after lone carriage returns", "<hierarchy>\n" + sphere + "\r\r  stray\n</hierarchy>\n", 2},
        // A character reference is white space only once decoded: the text starts at the '&'.
        {"after a character reference", "<hierarchy>\n" + sphere + "\n&#10;&#10;stray\n</hierarchy>\n", 3},
        {"after plain newlines", "<hierarchy>\n" + sphere + "\n\n\n  stray\n</hierarchy>\n", 5},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.what);
        const Error error = read_error(c.text);
        EXPECT_EQ(error.line, c.line) << error.to_string();
        EXPECT_NE(error.message.find("unexpected text"), std::string::npos) << error.to_string();
    }
}

TEST(XmlLargeFiles, ErrorDeepInALargeFileNamesItsLine) {
    const std::string bad = "radius=\"-2\"";
    const std::size_t at = 45001;  // a volume whose pos spans three lines precedes it
    const SphereFile large = sphere_file(large_count, {{at, bad}});
    const Error error = read_error(large.text);
    EXPECT_EQ(error.line, large.line_of_volume[at]) << error.to_string();
    // The same volume first in a small file: the same message, and the line found the same way.
    const SphereFile small = sphere_file(5, {{2, bad}});
    const Error small_error = read_error(small.text);
    EXPECT_EQ(small_error.line, small.line_of_volume[2]);
    EXPECT_EQ(error.message, small_error.message);
    EXPECT_EQ(error.file, "big.xml");
}

TEST(XmlLargeFiles, TheFirstOfManyBadVolumesIsReportedWhateverTheThreadCount) {
    // Every volume of the second half is bad too. With two or more threads another thread converts part of
    // that half and meets a fault there long before the first thread reaches the one fault of the first half.
    Faults faults{{29000, "radius=\"1\" colour=\"red\""}};
    for (std::size_t i = 30000; i < large_count; ++i) faults[i] = "radius=\"0\"";
    const SphereFile file = sphere_file(large_count, faults);
    for (const int threads : {1, 2, 4}) {
        for (int repeat = 0; repeat < 3; ++repeat) {
            SCOPED_TRACE(std::to_string(threads) + " threads, run " + std::to_string(repeat));
            tbb::task_arena arena(threads);
            const Error error = arena.execute([&] { return read_error(file.text); });
            EXPECT_EQ(error.line, file.line_of_volume[29000]) << error.to_string();
            EXPECT_EQ(error.message, "unknown attribute 'colour' on <volume type=\"sphere\">");
        }
    }
}

/// A nested file: one root volume over `count` leaf spheres; `inside` puts extra content into leaf i.
std::string nested_file(std::size_t count, std::size_t inside_at, const std::string& inside, std::size_t bad_at) {
    std::string text = "<hierarchy>\n<volume type=\"sphere\" pos=\"0 0 0\" radius=\"1e9\">\n";  // lines 1-2
    for (std::size_t i = 0; i < count; ++i) {
        const std::string radius = i == bad_at ? "-1" : "1";
        const std::string start = "<volume type=\"sphere\" pos=\"" + std::to_string(i) + " 0 0\" radius=\"" + radius + "\"";
        text += i == inside_at ? start + ">\n" + inside + "\n</volume>\n" : start + "/>\n";
    }
    return text + "</volume>\n</hierarchy>\n";
}

TEST(XmlLargeFiles, ProblemsOfStructureAndOfVolumesComeInDocumentOrder) {
    // Leaf i starts on line i + 3 up to the one holding the extra content, which takes three lines.
    const std::size_t no_fault = SIZE_MAX;
    const Error box_first = read_error(nested_file(large_count, 40000, "<box/>", 45000));
    EXPECT_EQ(box_first.line, 40000 + 4) << box_first.to_string();
    EXPECT_NE(box_first.message.find("unexpected element <box>"), std::string::npos);
    const Error volume_first = read_error(nested_file(large_count, 40000, "<box/>", 30000));
    EXPECT_EQ(volume_first.line, 30000 + 3) << volume_first.to_string();
    EXPECT_EQ(volume_first.message, "attribute 'radius' must be >= 0, found -1");
    // A bad volume holding the misplaced element: its own problem is met first.
    const Error same_volume = read_error(nested_file(large_count, 40000, "<box/>", 40000));
    EXPECT_EQ(same_volume.line, 40000 + 3) << same_volume.to_string();
    EXPECT_EQ(same_volume.message, "attribute 'radius' must be >= 0, found -1");
    // And the tree of a valid large file has a line for every node.
    const Result<XmlModel> valid = read_xml_string(nested_file(large_count, no_fault, "", no_fault), "nested.xml");
    ASSERT_TRUE(valid) << valid.error().to_string();
    ASSERT_EQ(valid->node_lines.size(), large_count + 1);
    EXPECT_EQ(valid->node_lines.front(), 2);
    EXPECT_EQ(valid->node_lines.back(), static_cast<int>(large_count) + 2);
}

TEST(XmlLargeFiles, TextInsideTheHierarchyIsReportedBeforeAnyVolume) {
    // As in the one-pass reader, <hierarchy>'s own content is checked before the volumes are read.
    SphereFile file = sphere_file(large_count, {{10, "radius=\"-1\""}});
    file.text.insert(file.text.rfind("</hierarchy>"), "  stray\n");
    const Error error = read_error(file.text);
    EXPECT_EQ(error.line, file.line_of_volume.back() + 1) << error.to_string();
    EXPECT_NE(error.message.find("unexpected text"), std::string::npos) << error.to_string();
    EXPECT_NE(error.message.find("stray"), std::string::npos) << error.to_string();
}

/// pugixml's own rendering of `text`: parsed (values decoded, nothing else changed) and saved the way the
/// writer used to save its DOM. The writer no longer builds one; its text must still be exactly this.
std::string pugixml_rendering(const std::string& text) {
    pugi::xml_document document;
    const pugi::xml_parse_result parsed =
        document.load_buffer(text.data(), text.size(), pugi::parse_declaration | pugi::parse_escapes, pugi::encoding_utf8);
    EXPECT_TRUE(parsed) << parsed.description();
    struct Collect final : pugi::xml_writer {
        void write(const void* data, std::size_t size) override { out.append(static_cast<const char*>(data), size); }
        std::string out;
    } collect;
    document.save(collect, "  ", pugi::format_indent, pugi::encoding_utf8);
    return collect.out;
}

TEST(XmlLargeFiles, WrittenTextIsWhatPugixmlWrites) {
    // Every byte value in a name (the escaping of & < > " ' and control characters, and raw non-ASCII bytes).
    std::vector<Primitive> primitives;
    for (int byte = 1; byte < 256; ++byte) {
        std::string name = "n";
        name += static_cast<char>(byte);
        name += 'e';
        primitives.push_back({Sphere{Vec3(byte, 0, 0), 0.5}, name});
    }
    primitives.push_back({Aabb{Vec3(0, 0, 0), Vec3(1, 2, 3)}, ""});
    primitives.push_back({Obb{Vec3(1, 2, 3), Mat3::Identity(), Vec3(0.5, 1e-300, 2e300)}, "box"});
    primitives.push_back({Capsule{Vec3(0, 0, -1), Vec3(0, 0, 1), 0.25}, "barrel"});
    const std::string flat = write_primitives_xml(primitives);
    EXPECT_EQ(flat, pugixml_rendering(flat));
    // Nested, wide (the root's children are formatted in groups) and deep.
    TreeAssembler assembler(primitives);
    std::vector<std::uint32_t> leaves;
    for (std::uint32_t i = 0; i < primitives.size(); ++i) leaves.push_back(assembler.add_leaf(i));
    const std::uint32_t inner = assembler.add_group(std::span(leaves).first(3), Sphere{Vec3(2, 0, 0), 3});
    std::vector<std::uint32_t> top{inner};
    top.insert(top.end(), leaves.begin() + 3, leaves.end());
    const std::uint32_t root = assembler.add_group(top, Aabb{Vec3(-1, -1, -1), Vec3(300, 5, 5)});
    const std::string nested = write_xml(std::move(assembler).finish(root));
    EXPECT_EQ(nested, pugixml_rendering(nested));
    EXPECT_EQ(write_xml(Bvh{}), pugixml_rendering(write_xml(Bvh{})));
}

TEST(XmlLargeFiles, LargeWrittenFilesAreWhatPugixmlWrites) {
    // Above the size at which the writer formats chunks of volumes side by side.
    std::vector<Primitive> primitives;
    for (std::size_t i = 0; i < 20000; ++i)
        primitives.push_back({Sphere{Vec3(static_cast<double>(i) * 0.1, 1.0 / static_cast<double>(i + 3), 0), 0.5},
                              i % 3 == 0 ? "" : "p&" + std::to_string(i)});
    const std::string flat = write_primitives_xml(primitives);
    EXPECT_EQ(flat, pugixml_rendering(flat));
    // A wide root: its children are formatted in groups side by side; and one subtree deeper.
    TreeAssembler assembler(primitives);
    std::vector<std::uint32_t> children;
    for (std::uint32_t i = 0; i < primitives.size(); ++i) children.push_back(assembler.add_leaf(i));
    const std::uint32_t pair = assembler.add_group(std::span(children).last(2), Sphere{Vec3(0, 0, 0), 1e4});
    children.resize(children.size() - 2);
    children.push_back(pair);
    const std::string nested = write_xml(std::move(assembler).finish(assembler.add_group(children, Sphere{Vec3(0, 0, 0), 1e5})));
    EXPECT_EQ(nested, pugixml_rendering(nested));
    const Result<XmlModel> model = read_xml_string(flat, "large.xml");
    ASSERT_TRUE(model) << model.error().to_string();
    ASSERT_EQ(model->primitives.size(), primitives.size());
    EXPECT_EQ(model->primitives[4].name, "p&4");
}

TEST(XmlLargeFiles, NamesEndAtANulAsPugixmlWroteThem) {
    const std::vector<Primitive> primitives{{Sphere{Vec3(0, 0, 0), 1}, std::string("ab\0cd", 5)},
                                            {Sphere{Vec3(1, 0, 0), 1}, std::string("\0x", 2)}};
    const std::string text = write_primitives_xml(primitives);
    EXPECT_NE(text.find("name=\"ab\" pos=\"0 0 0\""), std::string::npos) << text;
    EXPECT_NE(text.find("name=\"\" pos=\"1 0 0\""), std::string::npos) << text;
}

}  // namespace
}  // namespace hbvh
