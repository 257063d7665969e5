// SPDX-License-Identifier: MIT
// use_huge_pages_for_xml: pugixml's blocks from huge-page regions. What could go wrong: a block freed into the
// wrong place (one from malloc taken for a region's, or the reverse), blocks that overlap or are misaligned,
// a region unmapped while a block in it lives, or a region never unmapped. The oracle for the reading itself is
// the same text read with malloc's memory, before the switch.
#include "hbvh/io/xml_memory.hpp"

#include <gtest/gtest.h>
#include <pugixml.hpp>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "hbvh/builders/build.hpp"
#include "hbvh/io/xml.hpp"
#include "hbvh/scene/generate.hpp"

namespace hbvh {
namespace {

/// A document big enough that pugixml takes several 32 KiB blocks for it.
std::string many_elements(int count) {
    std::string text = "<root>";
    for (int i = 0; i < count; ++i) text += "<item index=\"" + std::to_string(i) + "\" kind=\"x\"/>";
    return text + "</root>";
}

/// The model written back: the writer prints every number in its shortest exact form, so two reads give the
/// same text exactly when they give the same primitives, names and tree.
std::string written(const XmlModel& model) {
    return model.hierarchy ? write_xml(*model.hierarchy) : write_primitives_xml(model.primitives);
}

TEST(XmlMemory, DocumentsFromBeforeTheSwitchAreFreedWithMalloc) {
    auto before = std::make_unique<pugi::xml_document>();
    ASSERT_TRUE(before->load_string(many_elements(5000).c_str()));
    use_huge_pages_for_xml();
    EXPECT_EQ(detail::xml_memory_use().regions, 0U);
    before.reset();  // malloc's blocks go back to free(), not into a region (ASan would see the mistake)

    pugi::xml_document after;
    ASSERT_TRUE(after.load_string(many_elements(5000).c_str()));
    EXPECT_EQ(detail::xml_memory_use().regions, 1U);
    EXPECT_GT(detail::xml_memory_use().live_blocks, 1U);
    EXPECT_EQ(std::distance(after.child("root").begin(), after.child("root").end()), 5000);
    after.reset();
    EXPECT_EQ(detail::xml_memory_use().regions, 0U) << "a region outlived its last block";
    EXPECT_EQ(detail::xml_memory_use().live_blocks, 0U);
}

TEST(XmlMemory, ModelsReadTheSameAsWithMalloc) {
    SceneOptions options;
    options.count = 3000;
    options.seed = 11;
    const std::vector<Primitive> primitives = generate_scene(options);
    const Result<Bvh> tree = build(primitives, Algorithm::binned);
    ASSERT_TRUE(tree.has_value());
    const std::string texts[] = {write_primitives_xml(primitives), write_xml(*tree)};

    std::vector<std::string> with_malloc;
    for (const std::string& text : texts) {
        const Result<XmlModel> model = read_xml_string(text, "malloc.xml");
        ASSERT_TRUE(model.has_value()) << model.error().to_string();
        with_malloc.push_back(written(*model));
    }
    use_huge_pages_for_xml();
    use_huge_pages_for_xml();  // twice changes nothing
    for (std::size_t i = 0; i < std::size(texts); ++i) {
        const Result<XmlModel> model = read_xml_string(texts[i], "regions.xml");
        ASSERT_TRUE(model.has_value()) << model.error().to_string();
        EXPECT_EQ(written(*model), with_malloc[i]);
        EXPECT_EQ(detail::xml_memory_use().regions, 0U) << "the reader's document left its region mapped";
    }
    // Errors too: the same message, the same line.
    const std::string bad = "<hierarchy>\n<volume type=\"sphere\" pos=\"0 0 0\" radius=\"-1\"/>\n</hierarchy>";
    const Result<XmlModel> refused = read_xml_string(bad, "bad.xml");
    ASSERT_FALSE(refused.has_value());
    EXPECT_EQ(refused.error().line, 2);
}

TEST(XmlMemory, BlocksAreAlignedDisjointAndSpanRegions) {
    use_huge_pages_for_xml();
    const pugi::allocation_function allocate = pugi::get_memory_allocation_function();
    const pugi::deallocation_function deallocate = pugi::get_memory_deallocation_function();
    // 70 MiB of pugixml's 32 KiB pages and a few odd sizes: more than one 64 MiB region.
    std::vector<std::pair<std::byte*, std::size_t>> blocks;
    for (std::size_t i = 0; i < 2240; ++i) {
        const std::size_t bytes = i % 97 == 5 ? 1 + i % 13 : 32768;
        auto* block = static_cast<std::byte*>(allocate(bytes));
        ASSERT_NE(block, nullptr);
        EXPECT_EQ(reinterpret_cast<std::uintptr_t>(block) % alignof(std::max_align_t), 0U);
        std::memset(block, static_cast<int>(i & 0xff), bytes);
        blocks.emplace_back(block, bytes);
    }
    EXPECT_EQ(detail::xml_memory_use().regions, 2U);
    EXPECT_EQ(detail::xml_memory_use().live_blocks, blocks.size());
    // Every block still holds its own pattern: none was handed out twice or overlaps another.
    for (std::size_t i = 0; i < blocks.size(); ++i) {
        const auto [block, bytes] = blocks[i];
        const bool intact = std::all_of(block, block + bytes, [&](std::byte b) { return b == static_cast<std::byte>(i & 0xff); });
        ASSERT_TRUE(intact) << "block " << i;
    }
    // A block larger than a quarter region comes from malloc and goes back to free().
    void* large = allocate(std::size_t{20} << 20);
    ASSERT_NE(large, nullptr);
    EXPECT_EQ(detail::xml_memory_use().live_blocks, blocks.size());
    deallocate(large);

    // Freed from the back, the second region goes when its last block does, and the first stays until then.
    while (blocks.size() > 1) {
        deallocate(blocks.back().first);
        blocks.pop_back();
        ASSERT_GE(detail::xml_memory_use().regions, 1U);
        // Blocks that live keep their contents while others in their region are freed.
        EXPECT_EQ(blocks.front().first[0], std::byte{0});
    }
    EXPECT_EQ(detail::xml_memory_use().regions, 1U);
    deallocate(blocks.front().first);
    EXPECT_EQ(detail::xml_memory_use().regions, 0U);
    EXPECT_EQ(detail::xml_memory_use().live_blocks, 0U);
}

}  // namespace
}  // namespace hbvh
