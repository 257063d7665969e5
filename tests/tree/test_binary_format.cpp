// SPDX-License-Identifier: MIT
// The .hbvh binary format: round trips of trees from several builders, names in UTF-8, primitive sets and
// single leaves; every truncation and every single-byte corruption refused; recomputed checksums leave only
// valid trees; versions, magic, counts and the file helpers. Every read is also made by QueryTree::read_binary,
// which must refuse the same bytes with the same words and otherwise give the tree the Bvh converts to.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstring>
#include <filesystem>
#include <iterator>
#include <limits>
#include <thread>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "hbvh/builders/build.hpp"
#include "hbvh/scene/generate.hpp"
#include "hbvh/tree/binary_format.hpp"
#include "hbvh/geometry/validation.hpp"
#include "hbvh/query/tandem_traversal.hpp"
#include "hbvh/tree/validate.hpp"
#include "support/tree_properties.hpp"

namespace hbvh {
namespace {

std::span<const std::byte> as_span(const std::string& bytes) { return std::as_bytes(std::span(bytes)); }

/// QueryTree::read_binary, which decodes straight into the query layout, against read_binary and then the
/// conversion of its Bvh: the same refusals with the same words, and otherwise the same query tree.
void expect_query_tree_agrees(const std::string& bytes, const Result<Bvh>& bvh) {
    const Result<QueryTree> direct = QueryTree::read_binary(as_span(bytes), "test.hbvh");
    if (!bvh) {
        ASSERT_FALSE(direct.has_value());
        EXPECT_EQ(direct.error().to_string(), bvh.error().to_string());
        return;
    }
    if (bvh->nodes.empty()) {  // a primitive set: nothing to query
        ASSERT_FALSE(direct.has_value());
        EXPECT_NE(direct.error().message.find("primitive set"), std::string::npos) << direct.error().message;
        return;
    }
    ASSERT_TRUE(direct.has_value()) << direct.error().to_string();
    const QueryTree converted(*bvh);
    ASSERT_EQ(direct->nodes().size(), converted.nodes().size());
    for (std::uint32_t i = 0; i < converted.nodes().size(); ++i) {
        const QueryNode& a = direct->nodes()[i];
        const QueryNode& b = converted.nodes()[i];
        ASSERT_TRUE(a.center == b.center && a.sphere_radius == b.sphere_radius && a.rotation == b.rotation &&
                    a.half_extents == b.half_extents && a.measure == b.measure && a.first_child == b.first_child &&
                    a.child_count == b.child_count && a.primitive == b.primitive && a.leaf_begin == b.leaf_begin &&
                    a.leaf_count == b.leaf_count && a.type == b.type && a.axis_aligned == b.axis_aligned)
            << "node " << i;
        ASSERT_TRUE(test_support::same_volume(direct->volume(i), converted.volume(i))) << "node " << i;
    }
    EXPECT_TRUE(std::ranges::equal(direct->leaves(), converted.leaves()));
    EXPECT_TRUE(std::ranges::equal(direct->primitive_nodes(), converted.primitive_nodes()));
    EXPECT_EQ(direct->stack_bound(), converted.stack_bound());
    EXPECT_EQ(direct->coordinate_bound(), converted.coordinate_bound());
    EXPECT_EQ(direct->extent_bound(), converted.extent_bound());
}

/// read_binary, with QueryTree::read_binary checked against it on the same bytes.
Result<Bvh> read(const std::string& bytes) {
    Result<Bvh> bvh = read_binary(as_span(bytes), "test.hbvh");
    expect_query_tree_agrees(bytes, bvh);
    return bvh;
}

std::uint64_t load_u64(const std::string& bytes, std::size_t at) {
    std::uint64_t value = 0;
    for (int i = 7; i >= 0; --i) value = (value << 8) | static_cast<unsigned char>(bytes[at + static_cast<std::size_t>(i)]);
    return value;
}
void store_u64(std::string& bytes, std::size_t at, std::uint64_t value) {
    for (std::size_t i = 0; i < 8; ++i) bytes[at + i] = static_cast<char>(value >> (8 * i));
}
/// Recomputes the trailing CRC-64 after an edit, so the edit reaches the checks behind the checksum.
void reseal(std::string& bytes) {
    const std::size_t at = bytes.size() - 8;
    store_u64(bytes, at, crc64_xz(as_span(bytes).first(at)));
}

void expect_same(const Bvh& a, const Bvh& b) {
    ASSERT_EQ(a.nodes.size(), b.nodes.size());
    ASSERT_EQ(a.primitives.size(), b.primitives.size());
    for (std::size_t i = 0; i < a.nodes.size(); ++i) {
        EXPECT_TRUE(test_support::same_volume(a.nodes[i].volume, b.nodes[i].volume)) << "node " << i;
        EXPECT_EQ(a.nodes[i].first_child, b.nodes[i].first_child) << "node " << i;
        EXPECT_EQ(a.nodes[i].child_count, b.nodes[i].child_count) << "node " << i;
        EXPECT_EQ(a.nodes[i].primitive, b.nodes[i].primitive) << "node " << i;
    }
    for (std::size_t i = 0; i < a.primitives.size(); ++i) {
        EXPECT_TRUE(test_support::same_volume(a.primitives[i].volume, b.primitives[i].volume)) << "primitive " << i;
        EXPECT_EQ(a.primitives[i].name, b.primitives[i].name) << "primitive " << i;
    }
}

std::vector<Primitive> named_scene(std::uint32_t count, std::uint64_t seed) {
    SceneOptions options;
    options.count = count;
    options.seed = seed;
    std::vector<Primitive> primitives = generate_scene(options);
    // Names in several scripts and lengths, one empty.
    const char* names[] = {"seat", "", "Stuhlbein-ä", "椅子の脚", "🪑 knob", "x"};
    for (std::size_t i = 0; i < primitives.size(); ++i) primitives[i].name = names[i % std::size(names)];
    return primitives;
}

Bvh built(const std::vector<Primitive>& primitives, Algorithm algorithm) {
    Result<Bvh> bvh = build(primitives, algorithm);
    EXPECT_TRUE(bvh.has_value()) << (bvh ? "" : bvh.error().to_string());
    return bvh ? std::move(bvh).value() : Bvh{};
}

/// Four spheres under an OBB root and a capsule group: all four kinds, small enough to corrupt byte by byte.
Bvh small_tree() {
    Bvh bvh;
    for (int i = 0; i < 4; ++i)
        bvh.primitives.push_back({Sphere{Vec3(2.0 * i, 0, 0), 0.5}, i == 2 ? "ä" : "s" + std::to_string(i)});
    bvh.nodes.push_back({Obb{Vec3(3, 0, 0), Mat3::Identity(), Vec3(4, 1, 1)}, 1, 2, 0});
    bvh.nodes.push_back({Aabb{Vec3(-1, -1, -1), Vec3(3, 1, 1)}, 3, 2, 0});
    bvh.nodes.push_back({Capsule{Vec3(4, 0, 0), Vec3(6, 0, 0), 1.0}, 5, 2, 0});
    for (std::uint32_t i = 0; i < 4; ++i) bvh.nodes.push_back({bvh.primitives[i].volume, 0, 0, i});
    return bvh;
}

TEST(BinaryFormat, Crc64MatchesTheStandardCheckValue) {
    const std::string check = "123456789";
    EXPECT_EQ(crc64_xz(as_span(check)), 0x995DC9BBDF1939FAULL);
    EXPECT_EQ(crc64_xz({}), 0u);
    // The 8-byte loop and the byte tail agree: every split of the same bytes gives one CRC (a longer input).
    const std::string longer = "The quick brown fox jumps over the lazy dog";
    EXPECT_EQ(crc64_xz(as_span(longer)), 0x5B5EB8C2E54AA1C4ULL);
}

/// CRC-64/XZ one bit at a time, straight from its definition: the reference for the fast paths.
std::uint64_t crc64_bitwise(const unsigned char* p, std::size_t n) {
    std::uint64_t crc = ~std::uint64_t{0};
    for (std::size_t i = 0; i < n; ++i) {
        crc ^= p[i];
        for (int bit = 0; bit < 8; ++bit) crc = (crc & 1) != 0 ? (crc >> 1) ^ 0xC96C5795D7870F42ULL : crc >> 1;
    }
    return ~crc;
}

TEST(BinaryFormat, Crc64FastPathsMatchTheBitwiseDefinition) {
    // Every length across the switch from tables to carry-less folding (256 bytes), the 64- and 16-byte
    // steps and the tail, at several alignments, and one long buffer.
    std::string bytes(1 << 16, '\0');
    std::uint64_t state = 0x9E3779B97F4A7C15ULL;
    for (char& c : bytes) {
        state = state * 6364136223846793005ULL + 1442695040888963407ULL;
        c = static_cast<char>(state >> 56);
    }
    const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
    for (std::size_t offset : {0u, 1u, 7u, 13u})
        for (std::size_t n = 0; n <= 1200; ++n)
            ASSERT_EQ(crc64_xz(as_span(bytes).subspan(offset, n)), crc64_bitwise(data + offset, n))
                << "length " << n << " at offset " << offset;
    EXPECT_EQ(crc64_xz(as_span(bytes)), crc64_bitwise(data, bytes.size()));
}

TEST(BinaryFormat, LayoutIsLittleEndianFieldByField) {
    Bvh set;
    set.primitives.push_back({Sphere{Vec3(1, 2, 3), 0.5}, "a"});
    const std::string bytes = write_binary(set);
    // header 40 + sphere record (1 + 4 x 8) + name (4 + 1) + checksum 8
    ASSERT_EQ(bytes.size(), 40u + 33u + 5u + 8u);
    EXPECT_EQ(std::memcmp(bytes.data(), binary_magic.data(), 8), 0);
    EXPECT_EQ(bytes.substr(8, 4), std::string("\x01\x00\x00\x00", 4));  // version 1
    EXPECT_EQ(bytes.substr(12, 4), std::string(4, '\0'));                // flags
    EXPECT_EQ(load_u64(bytes, 16), bytes.size());                         // file size
    EXPECT_EQ(load_u64(bytes, 24), 0u);                                   // nodes: a primitive set
    EXPECT_EQ(load_u64(bytes, 32), 1u);                                   // primitives
    EXPECT_EQ(bytes[40], 2);                                              // kind: sphere
    EXPECT_EQ(bytes.substr(41, 8), std::string("\x00\x00\x00\x00\x00\x00\xf0\x3f", 8));  // 1.0
    EXPECT_EQ(load_u64(bytes, 41 + 24), std::bit_cast<std::uint64_t>(0.5));
    EXPECT_EQ(bytes.substr(73, 5), std::string("\x01\x00\x00\x00" "a", 5));
    EXPECT_EQ(load_u64(bytes, 78), crc64_xz(as_span(bytes).first(78)));
}

TEST(BinaryFormat, TreesFromSeveralBuildersRoundTrip) {
    const std::vector<Primitive> primitives = named_scene(60, 11);
    for (Algorithm algorithm : {Algorithm::two_level, Algorithm::split, Algorithm::merge, Algorithm::insertion,
                                Algorithm::obb_tree, Algorithm::insertion_haber}) {
        SCOPED_TRACE(std::string(to_string(algorithm)));
        const Bvh original = built(primitives, algorithm);
        const std::string bytes = write_binary(original);
        Result<Bvh> back = read(bytes);
        ASSERT_TRUE(back.has_value()) << back.error().to_string();
        expect_same(original, back.value());
        EXPECT_EQ(write_binary(back.value()), bytes);  // canonical
        EXPECT_TRUE(validate(back.value()));
    }
}

TEST(BinaryFormat, SingleLeafAndPrimitiveSetRoundTrip) {
    Bvh leaf;
    leaf.primitives.push_back({Capsule{Vec3(0, 0, 0), Vec3(0, 0, 1), 0.25}, "only"});
    leaf.nodes.push_back({leaf.primitives[0].volume, 0, 0, 0});
    Result<Bvh> back = read(write_binary(leaf));
    ASSERT_TRUE(back.has_value()) << back.error().to_string();
    expect_same(leaf, back.value());

    Bvh set;
    set.primitives = named_scene(7, 3);
    back = read(write_binary(set));
    ASSERT_TRUE(back.has_value()) << back.error().to_string();
    EXPECT_TRUE(back->nodes.empty());
    expect_same(set, back.value());
}

TEST(BinaryFormat, NamesMustBeUtf8WithoutNul) {
    // The reader refuses such names (written here behind a good checksum: a placeholder of the same length,
    // replaced in the bytes, then resealed)...
    const std::vector<std::string> bad_names{std::string("\xff"),         std::string("ab\xc3"),
                                             std::string("\xc0\x80"),     std::string("\xed\xa0\x80"),
                                             std::string("a\0b", 3),      std::string("\xf4\x90\x80\x80")};
    for (const std::string& bad : bad_names) {
        Bvh set;
        set.primitives.push_back({Sphere{Vec3(0, 0, 0), 1.0}, std::string(bad.size(), 'x')});
        std::string bytes = write_binary(set);
        const std::size_t at = bytes.size() - 8 - bad.size();  // the last name, then the 8-byte checksum
        ASSERT_EQ(bytes.substr(at, bad.size()), std::string(bad.size(), 'x'));
        bytes.replace(at, bad.size(), bad);
        reseal(bytes);
        Result<Bvh> back = read(bytes);
        ASSERT_FALSE(back.has_value()) << "accepted a bad name";
        EXPECT_TRUE(back.error().message.find("NUL") != std::string::npos ||
                    back.error().message.find("not UTF-8") != std::string::npos)
            << back.error().message;
    }
    // ... and the writer never makes one: each byte that starts no character becomes U+FFFD, a NUL ends the name
    // (a Latin-1 name from an old asset was written as it was, and the file could not be read back).
    const std::vector<std::pair<std::string, std::string>> repaired{
        {"caf\xe9", "caf\xef\xbf\xbd"},
        {"ab\xc3", "ab\xef\xbf\xbd"},
        {"\xc0\x80z", "\xef\xbf\xbd\xef\xbf\xbdz"},
        {std::string("a\0b", 3), "a"},
        {"ok \xc3\xa9", "ok \xc3\xa9"}};
    Bvh set;
    for (const auto& [name, expected] : repaired) set.primitives.push_back({Sphere{Vec3(0, 0, 0), 1.0}, name});
    const Result<Bvh> back = read(write_binary(set));
    ASSERT_TRUE(back.has_value()) << back.error().to_string();
    for (std::size_t i = 0; i < repaired.size(); ++i) EXPECT_EQ(back->primitives[i].name, repaired[i].second) << i;
}

TEST(BinaryFormat, EveryTruncationIsRefused) {
    const std::string bytes = write_binary(small_tree());
    ASSERT_TRUE(read(bytes).has_value());
    for (std::size_t length = 0; length < bytes.size(); ++length) {
        Result<Bvh> back = read(bytes.substr(0, length));
        ASSERT_FALSE(back.has_value()) << "accepted the first " << length << " bytes";
        EXPECT_EQ(back.error().file, "test.hbvh");
        EXPECT_EQ(back.error().line, 0);
        EXPECT_EQ(back.error().message.rfind("offset ", 0), 0u) << back.error().message;
        if (length > 0) {
            EXPECT_NE(back.error().message.find("truncated"), std::string::npos) << back.error().message;
        }
    }
}

TEST(BinaryFormat, AHeaderDeclaringLessThanAHeaderAndChecksumIsRefusedAtItsSizeField) {
    // A whole header whose declared size (bytes 16-23, little-endian) is the 44 bytes there are: not truncated
    // by the header's account, but too short for the checksum.
    std::string bytes = write_binary(small_tree()).substr(0, 44);
    for (std::size_t k = 0; k < 8; ++k) bytes[16 + k] = static_cast<char>(k == 0 ? 44 : 0);
    Result<Bvh> back = read(bytes);
    ASSERT_FALSE(back.has_value());
    EXPECT_EQ(back.error().message,
              "offset 16: the header says the file has 44 bytes, fewer than its 40-byte header and 8-byte checksum");
    // Cut from a real file instead, the same length is truncated by the header's account.
    back = read(write_binary(small_tree()).substr(0, 44));
    ASSERT_FALSE(back.has_value());
    EXPECT_EQ(back.error().message.rfind("offset 44: file is truncated: the header says ", 0), 0u) << back.error().message;
}

TEST(BinaryFormat, ALeafThatIsNotItsPrimitiveIsRefusedByBothReaders) {
    // A sound tree in every other way, checksum and all, whose leaf of primitive 1 is a larger sphere: queries
    // would test the leaf and report primitive 1 (the reviewed file gave 64 pairs where 8 were true).
    Bvh bigger_leaf = small_tree();
    std::get<Sphere>(bigger_leaf.nodes[4].volume).radius = 5.0;
    const std::string bytes = write_binary(bigger_leaf);
    const Result<Bvh> back = read(bytes);
    ASSERT_FALSE(back.has_value());
    // Node 4's record: header 40 + OBB 133 + AABB 61 + capsule (1 + 7 x 8 + 12) 69 + sphere 45.
    EXPECT_EQ(back.error().message, "offset " + std::to_string(40 + 133 + 61 + 69 + 45) +
                                        ": node 4: leaf volume differs from its primitive 1's");
    expect_query_tree_agrees(bytes, back);
    // Another kind in the leaf is refused alike.
    Bvh other_kind = small_tree();
    other_kind.nodes[6].volume = Aabb{Vec3(5.5, -0.5, -0.5), Vec3(6.5, 0.5, 0.5)};
    const Result<Bvh> kind_back = read(write_binary(other_kind));
    ASSERT_FALSE(kind_back.has_value());
    EXPECT_NE(kind_back.error().message.find("node 6: leaf volume differs from its primitive 3's"), std::string::npos)
        << kind_back.error().message;
    // And check_structure refuses such a Bvh made in memory.
    EXPECT_FALSE(check_structure(bigger_leaf));
}

TEST(BinaryFormat, EverySingleByteCorruptionIsRefused) {
    const std::string bytes = write_binary(small_tree());
    for (std::size_t at = 0; at < bytes.size(); ++at)
        for (unsigned flip : {0x01u, 0x80u, 0xFFu}) {
            std::string corrupted = bytes;
            corrupted[at] = static_cast<char>(static_cast<unsigned char>(corrupted[at]) ^ flip);
            Result<Bvh> back = read(corrupted);
            ASSERT_FALSE(back.has_value()) << "byte " << at << " ^ " << flip << " accepted";
            // Past the header's fields that are checked first, it is the checksum that notices.
            if (at >= 24) {
                EXPECT_NE(back.error().message.find("checksum mismatch"), std::string::npos) << back.error().message;
            }
        }
}

TEST(BinaryFormat, ResealedCorruptionGivesAnErrorOrAValidTree) {
    const std::string bytes = write_binary(small_tree());
    std::size_t accepted = 0, refused = 0;
    for (std::size_t at = 0; at + 8 < bytes.size(); ++at)
        for (unsigned flip : {0x01u, 0x10u, 0x80u, 0xFFu}) {
            std::string corrupted = bytes;
            corrupted[at] = static_cast<char>(static_cast<unsigned char>(corrupted[at]) ^ flip);
            reseal(corrupted);
            Result<Bvh> back = read(corrupted);
            if (!back) {
                ++refused;
                EXPECT_EQ(back.error().message.find("checksum"), std::string::npos) << back.error().message;
                continue;
            }
            ++accepted;
            // Accepted only as a sound tree, which is exactly what the bytes say.
            EXPECT_TRUE(check_structure(back.value())) << "byte " << at;
            EXPECT_EQ(write_binary(back.value()), corrupted) << "byte " << at;
        }
    // Both happen: a low mantissa bit of a coordinate is still a tree, a child count of 3 is not.
    EXPECT_GT(accepted, 0u);
    EXPECT_GT(refused, 0u);
}

TEST(BinaryFormat, MalformedTreesAndBadGeometryBehindAGoodChecksumAreRefused) {
    Bvh single_child = small_tree();
    single_child.nodes[2].child_count = 1;
    Result<Bvh> back = read(write_binary(single_child));
    ASSERT_FALSE(back.has_value());
    // Node 2's record: header 40 + node 0 (OBB: 1 + 15 x 8 + 12) + node 1 (AABB: 1 + 6 x 8 + 12).
    EXPECT_EQ(back.error().message, "offset " + std::to_string(40 + 133 + 61) + ": node 2: inner node with a single child");

    Bvh nan_node = small_tree();
    std::get<Aabb>(nan_node.nodes[1].volume).max.x() = std::numeric_limits<double>::quiet_NaN();
    back = read(write_binary(nan_node));
    ASSERT_FALSE(back.has_value());
    EXPECT_EQ(back.error().message.rfind("offset 173: node 1:", 0), 0u) << back.error().message;

    Bvh negative = small_tree();
    negative.nodes.clear();
    std::get<Sphere>(negative.primitives[3].volume).radius = -1.0;
    back = read(write_binary(negative));
    ASSERT_FALSE(back.has_value());
    // The fourth sphere record of the primitive set: 40 + 3 x 33.
    EXPECT_EQ(back.error().message.rfind("offset 139: primitive 3", 0), 0u) << back.error().message;

    Bvh shared_leaf = small_tree();
    shared_leaf.nodes[6].primitive = 0;
    EXPECT_FALSE(read(write_binary(shared_leaf)).has_value());

    std::string unknown_kind = write_binary(small_tree());
    unknown_kind[40] = 9;
    reseal(unknown_kind);
    back = read(unknown_kind);
    ASSERT_FALSE(back.has_value());
    EXPECT_EQ(back.error().message.rfind("offset 40: unknown volume kind 9", 0), 0u) << back.error().message;
}

/// A rotation about z by `angle`, then its first entry scaled by 1 + `skew` (no longer exactly orthonormal).
Mat3 skewed_rotation(double angle, double skew) {
    Mat3 r;
    r << std::cos(angle), -std::sin(angle), 0, std::sin(angle), std::cos(angle), 0, 0, 0, 1;
    r(0, 0) *= 1.0 + skew;
    return r;
}

TEST(BinaryFormat, OnTheFlyChecksAgreeWithTheFullChecks) {
    // The reader tests each record as it decodes it and runs check_structure / validate_primitives only when
    // something looks wrong; whatever the case, it must accept exactly what those accept, with their words.
    const double tiny = std::numeric_limits<double>::denorm_min(), huge = std::numeric_limits<double>::max();
    const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
    std::vector<std::pair<std::string, Bvh>> cases;
    auto add = [&](std::string what, auto edit) {
        Bvh tree = small_tree();
        edit(tree);
        cases.emplace_back(what, tree);
        Bvh set = tree;  // the same primitives as a primitive set, where the edit touched them
        set.nodes.clear();
        cases.emplace_back(what + " (primitive set)", set);
    };
    auto root = [](Bvh& b) -> Obb& { return std::get<Obb>(b.nodes[0].volume); };
    auto leaf_sphere = [](Bvh& b) -> Sphere& { return std::get<Sphere>(b.primitives[1].volume); };
    add("unchanged", [](Bvh&) {});
    // Rotations at both sides of rotation_tolerance (|R^T R - I| is about 2 x skew here).
    for (const double skew : {1e-12, 1e-10, 2e-10, 3e-10, 4e-10, 6e-10, 1e-9})
        add("rotation skewed by " + std::to_string(skew), [&](Bvh& b) { root(b).rotation = skewed_rotation(0.3, skew); });
    add("reflection", [&](Bvh& b) { root(b).rotation(2, 2) = -1.0; });
    add("NaN rotation", [&](Bvh& b) { root(b).rotation(1, 2) = nan; });
    add("infinite centre", [&](Bvh& b) { root(b).center.y() = inf; });
    add("half extent 0", [&](Bvh& b) { root(b).half_extents.x() = 0.0; });
    add("subnormal half extent", [&](Bvh& b) { root(b).half_extents.z() = tiny; });
    add("negative half extent", [&](Bvh& b) { root(b).half_extents.y() = -1.0; });
    add("half extent overflowing when doubled", [&](Bvh& b) { root(b).half_extents.x() = huge; });
    add("box corners with NaN", [&](Bvh& b) { std::get<Aabb>(b.nodes[1].volume).min.z() = nan; });
    add("box turned inside out", [](Bvh& b) { std::get<Aabb>(b.nodes[1].volume).max.x() = -2.0; });
    add("flat box", [](Bvh& b) { std::get<Aabb>(b.nodes[1].volume).max.x() = -1.0; });
    add("box extent overflowing", [&](Bvh& b) {
        std::get<Aabb>(b.nodes[1].volume).min.x() = -huge;
        std::get<Aabb>(b.nodes[1].volume).max.x() = huge;
    });
    add("box extent subnormal", [&](Bvh& b) { std::get<Aabb>(b.nodes[1].volume).max.x() = -1.0 + 0x1p-60; });
    add("radius 0", [&](Bvh& b) { leaf_sphere(b).radius = 0.0; });
    add("radius subnormal", [&](Bvh& b) { leaf_sphere(b).radius = tiny; });
    add("radius -0", [&](Bvh& b) { leaf_sphere(b).radius = -0.0; });
    add("radius NaN", [&](Bvh& b) { leaf_sphere(b).radius = nan; });
    add("sphere centre infinite", [&](Bvh& b) { leaf_sphere(b).center.x() = -inf; });
    add("capsule length overflowing", [&](Bvh& b) {
        std::get<Capsule>(b.nodes[2].volume).p0.x() = -huge;
        std::get<Capsule>(b.nodes[2].volume).p1.x() = huge;
    });
    add("capsule centre overflowing", [&](Bvh& b) {
        std::get<Capsule>(b.nodes[2].volume).p0.x() = huge;
        std::get<Capsule>(b.nodes[2].volume).p1.x() = huge;
    });
    add("capsule radius negative", [](Bvh& b) { std::get<Capsule>(b.nodes[2].volume).radius = -1.0; });
    add("leaf of a missing primitive", [](Bvh& b) { b.nodes[5].primitive = 4; });
    add("two leaves of one primitive", [](Bvh& b) { b.nodes[6].primitive = 1; });
    add("single child", [](Bvh& b) { b.nodes[1].child_count = 1; });
    add("children out of order", [](Bvh& b) { std::swap(b.nodes[1].first_child, b.nodes[2].first_child); });
    add("child range past the end", [](Bvh& b) { b.nodes[2].child_count = 3; });
    add("a node nobody's child", [](Bvh& b) {
        b.nodes[0].child_count = 2;
        b.nodes[2].child_count = 0;  // now a leaf, with node 2's primitive (0), which node 3 has too
    });
    add("a primitive in no leaf", [](Bvh& b) { b.primitives.push_back(b.primitives[0]); });
    std::size_t refused = 0;
    for (const auto& [what, bvh] : cases) {
        const Status expected = bvh.nodes.empty() ? validate_primitives(bvh.primitives) : check_structure(bvh);
        const Result<Bvh> back = read(write_binary(bvh));
        ASSERT_EQ(back.has_value(), expected.has_value()) << what << ": " << (back ? "" : back.error().message);
        if (back) {
            expect_same(bvh, back.value());
            continue;
        }
        ++refused;
        const std::string& message = back.error().message;
        EXPECT_EQ(message.substr(message.find(": ") + 2), expected.error().message) << what;
    }
    EXPECT_GE(refused, 25u);  // most edits make a refusal (those of nodes not in the primitive-set copies)
}

TEST(BinaryFormat, FileHelpersReadFromAPipe) {
    // No size to go by: the reader grows its buffer as the bytes come (here more than eight 64 KiB chunks). The
    // fifo is opened once: opened, closed and reopened, it would leave the writer without a reader (SIGPIPE).
    const std::filesystem::path dir = std::filesystem::path(testing::TempDir()) / "hbvh_binary_format_pipe";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    const std::filesystem::path fifo = dir / "tree.hbvh";
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    const Bvh original = built(named_scene(6'000, 9), Algorithm::two_level);
    const std::string bytes = write_binary(original);
    ASSERT_GT(bytes.size(), 8u * 65536u);
    std::thread writer([&] {
        const int fd = ::open(fifo.c_str(), O_WRONLY | O_CLOEXEC);
        if (fd < 0) return;
        for (std::string_view rest = bytes; !rest.empty();) {
            // Odd-sized writes, so the reads end anywhere.
            const ssize_t written = ::write(fd, rest.data(), std::min<std::size_t>(rest.size(), 70'001));
            if (written <= 0) break;
            rest.remove_prefix(static_cast<std::size_t>(written));
        }
        ::close(fd);
    });
    Result<Bvh> back = read_binary_file(fifo);
    writer.join();
    ASSERT_TRUE(back.has_value()) << back.error().to_string();
    expect_same(original, back.value());
    std::filesystem::remove_all(dir);
}

TEST(BinaryFormat, OtherVersionsMagicAndTrailingBytesAreRefused) {
    std::string bytes = write_binary(small_tree());
    std::string newer = bytes;
    newer[8] = 2;
    reseal(newer);
    Result<Bvh> back = read(newer);
    ASSERT_FALSE(back.has_value());
    EXPECT_EQ(back.error().message, "offset 8: format version 2 is not supported (this reader reads version 1)");

    back = read("<?xml version=\"1.0\"?><hierarchy/>");
    ASSERT_FALSE(back.has_value());
    EXPECT_EQ(back.error().message, "offset 0: not an .hbvh file (wrong magic bytes)");

    back = read(bytes + "xx");
    ASSERT_FALSE(back.has_value());
    EXPECT_NE(back.error().message.find("2 bytes after the end"), std::string::npos) << back.error().message;

    back = read(write_binary(Bvh{}));
    ASSERT_FALSE(back.has_value());
    EXPECT_NE(back.error().message.find("no primitives"), std::string::npos) << back.error().message;
}

TEST(BinaryFormat, HugeCountsAreRefusedBeforeAllocating) {
    const std::string bytes = write_binary(small_tree());
    for (std::uint64_t count : {std::uint64_t{1} << 40, std::uint64_t{UINT32_MAX}, std::uint64_t{14}, ~std::uint64_t{0}}) {
        std::string nodes = bytes;
        store_u64(nodes, 24, count);
        reseal(nodes);
        Result<Bvh> back = read(nodes);
        ASSERT_FALSE(back.has_value()) << count;
        EXPECT_EQ(back.error().message.rfind("offset 24: node count", 0), 0u) << back.error().message;

        std::string primitives = bytes;
        store_u64(primitives, 32, count);
        reseal(primitives);
        back = read(primitives);
        ASSERT_FALSE(back.has_value()) << count;
        EXPECT_EQ(back.error().message.rfind("offset 32: primitive count", 0), 0u) << back.error().message;
    }
}

/// The size of a volume record of `volume`, from the layout table of docs/formats.md (not from the reader).
std::size_t record_size(const BoundingVolume& volume) {
    constexpr std::size_t doubles[] = {6, 15, 4, 7};
    return 1 + 8 * doubles[volume.index()];
}

// A file of a few megabytes takes the reader's other path: mapped rather than read, and decoded by two tasks at
// once (the checksum and the nodes, the primitives). It must load the same tree and name the same first problem
// in file order as the small files above.
TEST(BinaryFormat, LargeFilesLoadTheSameAndReportTheFirstProblemInFileOrder) {
    const Bvh original = built(named_scene(12000, 11), Algorithm::two_level);
    const std::string bytes = write_binary(original);
    ASSERT_GT(bytes.size(), std::size_t{1} << 20);  // past both thresholds of the reader
    Result<Bvh> back = read(bytes);
    ASSERT_TRUE(back.has_value()) << back.error().to_string();
    expect_same(original, back.value());

    const std::filesystem::path dir = std::filesystem::path(testing::TempDir()) / "hbvh_binary_large_test";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    const std::filesystem::path file = dir / "large.hbvh";
    ASSERT_TRUE(write_binary_file(file, original));
    back = read_binary_file(file);
    ASSERT_TRUE(back.has_value()) << back.error().to_string();
    expect_same(original, back.value());
    // Straight into the query layout from the (mapped) file: the tree read_binary's Bvh converts to.
    const Result<QueryTree> loaded = QueryTree::read_binary_file(file);
    ASSERT_TRUE(loaded.has_value()) << loaded.error().to_string();
    ASSERT_EQ(loaded->nodes().size(), original.nodes.size());
    EXPECT_TRUE(std::ranges::equal(loaded->leaves(), QueryTree(original).leaves()));
    const Result<QueryTree> missing = QueryTree::read_binary_file(dir / "missing.hbvh");
    ASSERT_FALSE(missing.has_value());
    EXPECT_EQ(missing.error().file, (dir / "missing.hbvh").string());

    // Where the records are, by the layout: the last node's record, the primitives' first and last.
    std::size_t last_node_at = 40;
    for (std::size_t i = 0; i + 1 < original.nodes.size(); ++i) last_node_at += record_size(original.nodes[i].volume) + 12;
    const std::size_t primitives_at = last_node_at + record_size(original.nodes.back().volume) + 12;
    std::size_t last_primitive_at = primitives_at;
    for (std::size_t i = 0; i + 1 < original.primitives.size(); ++i) last_primitive_at += record_size(original.primitives[i].volume);
    const std::size_t last = original.primitives.size() - 1;

    // An unknown kind in the last primitive record alone, then also in the last node record: the node is first.
    std::string bad_kind = bytes;
    bad_kind[last_primitive_at] = 7;
    reseal(bad_kind);
    back = read(bad_kind);
    ASSERT_FALSE(back.has_value());
    EXPECT_EQ(back.error().message.rfind("offset " + std::to_string(last_primitive_at) + ": unknown volume kind 7", 0), 0u)
        << back.error().message;
    bad_kind[last_node_at] = 8;
    reseal(bad_kind);
    back = read(bad_kind);
    ASSERT_FALSE(back.has_value());
    EXPECT_EQ(back.error().message.rfind("offset " + std::to_string(last_node_at) + ": unknown volume kind 8", 0), 0u)
        << back.error().message;
    // Not resealed, the same edits are a corrupted file, whatever they would have been behind a good checksum.
    bad_kind[last_node_at + 3] ^= 0x10;
    back = read(bad_kind);
    ASSERT_FALSE(back.has_value());
    EXPECT_NE(back.error().message.find("checksum mismatch"), std::string::npos) << back.error().message;

    // A negative radius in the last primitive: found on the fly, then worded by validate_primitives.
    Bvh negative = original;
    std::visit([](auto& volume) {
        if constexpr (requires { volume.radius; }) volume.radius = -1.0;
        else if constexpr (requires { volume.half_extents; }) volume.half_extents.x() = -1.0;
        else volume.max.x() = volume.min.x() - 1.0;
    }, negative.primitives[last].volume);
    back = read(write_binary(negative));
    ASSERT_FALSE(back.has_value());
    EXPECT_EQ(back.error().message.rfind("offset " + std::to_string(last_primitive_at) + ": primitive " + std::to_string(last), 0), 0u)
        << back.error().message;

    // An impossible node count: named after the checksum, before anything is decoded.
    std::string bad_count = bytes;
    store_u64(bad_count, 24, bytes.size());
    reseal(bad_count);
    back = read(bad_count);
    ASSERT_FALSE(back.has_value());
    EXPECT_EQ(back.error().message.rfind("offset 24: node count", 0), 0u) << back.error().message;
    std::filesystem::remove_all(dir);
}

TEST(BinaryFormat, FileHelpersWriteAtomicallyAndNameTheFile) {
    const std::filesystem::path dir = std::filesystem::path(testing::TempDir()) / "hbvh_binary_format_test";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    const Bvh original = built(named_scene(30, 5), Algorithm::split);
    const std::filesystem::path file = dir / "tree.hbvh";
    ASSERT_TRUE(write_binary_file(file, original));
    ASSERT_TRUE(write_binary_file(file, original));  // over an existing file
    Result<Bvh> back = read_binary_file(file);
    ASSERT_TRUE(back.has_value()) << back.error().to_string();
    expect_same(original, back.value());
    // Nothing but the file is left in the directory (no temporary files).
    EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir), std::filesystem::directory_iterator()), 1);

    back = read_binary_file(dir / "missing.hbvh");
    ASSERT_FALSE(back.has_value());
    EXPECT_EQ(back.error().file, (dir / "missing.hbvh").string());
    EXPECT_NE(back.error().message.find("cannot open"), std::string::npos);
    EXPECT_FALSE(read_binary_file(dir).has_value());
    EXPECT_FALSE(write_binary_file(dir / "no_such_dir" / "x.hbvh", original));
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace hbvh
