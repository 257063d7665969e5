// SPDX-License-Identifier: MIT
// The .hbvh binary format (docs/formats.md, "The binary format"): its records encoded and decoded, explicit
// little-endian fields. The checksum is crc64.cpp; files (mapping, the atomic write) are binary_file.cpp.
#include "hbvh/tree/binary_format.hpp"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <optional>
#include <system_error>
#include <vector>

#include <tbb/task_group.h>

#include "hbvh/geometry/validation.hpp"
#include "hbvh/tree/validate.hpp"
#include "../memory/huge_pages.hpp"
#include "binary_decoding.hpp"
#include "little_endian.hpp"
#include "utf8.hpp"

namespace hbvh {
namespace {

using detail::load_u32_le;
using detail::load_u64_le;
using detail::store_u32_le;
using detail::store_u64_le;

// Sizes of the fixed parts (docs/formats.md's layout table).
constexpr std::size_t binary_header_size = 40;  // magic 8, version 4, flags 4, file size 8, node and primitive counts 8 + 8
constexpr std::size_t binary_checksum_size = 8;
constexpr std::size_t binary_node_links_size = 12;  // first_child, child_count, primitive: u32 each
// The smallest records (a sphere: kind byte + 4 doubles), which bound the counts a file of n bytes can hold.
constexpr std::size_t binary_min_volume_size = 1 + 4 * 8;
constexpr std::size_t binary_min_node_size = binary_min_volume_size + binary_node_links_size;
constexpr std::size_t binary_min_primitive_size = binary_min_volume_size + 4;  // + the name's length field

/// Doubles stored for each BvType, in variant order: aabb min, max; obb centre, rotation (row-major),
/// half extents; sphere centre, radius; capsule p0, p1, radius.
constexpr std::array<std::size_t, bv_type_count> binary_double_count{6, 15, 4, 7};

/// The numbers of a volume in file order.
std::size_t volume_doubles(const BoundingVolume& volume, std::array<double, 15>& out) {
    std::size_t n = 0;
    auto put = [&](const Vec3& v) {
        for (int i = 0; i < 3; ++i) out[n++] = v[i];
    };
    std::visit(Overloaded{[&](const Aabb& b) {
                              put(b.min);
                              put(b.max);
                          },
                          [&](const Obb& b) {
                              put(b.center);
                              for (int r = 0; r < 3; ++r)
                                  for (int c = 0; c < 3; ++c) out[n++] = b.rotation(r, c);
                              put(b.half_extents);
                          },
                          [&](const Sphere& s) {
                              put(s.center);
                              out[n++] = s.radius;
                          },
                          [&](const Capsule& c) {
                              put(c.p0);
                              put(c.p1);
                              out[n++] = c.radius;
                          }},
               volume);
    return n;
}

// True when volume_problem(volume) finds nothing, decided without composing its messages (which costs more
// than the test when it runs for each of a million records): finite numbers, sizes 0 or normal and positive,
// derived numbers (a box's extent, a capsule's length and centre) finite, a proper rotation. These may say no
// to a volume that volume_problem accepts (a rotation near the tolerance), never the other way round: the
// loader runs the full checks, for the verdict and the words, whenever one says no.

/// x * 0 is 0 for a finite x and NaN otherwise, and NaN survives a sum: one comparison for many numbers.
double zero_if_finite(const Vec3& v) { return v.x() * 0.0 + v.y() * 0.0 + v.z() * 0.0; }
/// What size_problem accepts: finite, not negative, not subnormal (NaN fails both comparisons).
bool is_usable_size(double size) {
    return size == 0.0 || (size >= std::numeric_limits<double>::min() && size <= std::numeric_limits<double>::max());
}
bool are_usable_sizes(const Vec3& sizes) {
    return is_usable_size(sizes.x()) & is_usable_size(sizes.y()) & is_usable_size(sizes.z());
}
bool is_surely_usable(const Aabb& box) {
    return zero_if_finite(box.min) + zero_if_finite(box.max) == 0.0 && are_usable_sizes(Vec3(box.max - box.min));
}
bool is_surely_usable(const Sphere& sphere) { return zero_if_finite(sphere.center) == 0.0 && is_usable_size(sphere.radius); }
bool is_surely_usable(const Capsule& capsule) {
    return zero_if_finite(capsule.p0) + zero_if_finite(capsule.p1) + zero_if_finite(capsule.center()) == 0.0 &&
           std::isfinite(capsule.length()) && is_usable_size(capsule.radius);
}
bool is_surely_usable(const Obb& box) {
    const Mat3& r = box.rotation;
    if (!(zero_if_finite(box.center) + zero_if_finite(Vec3(2.0 * box.half_extents)) + zero_if_finite(r.col(0)) +
              zero_if_finite(r.col(1)) + zero_if_finite(r.col(2)) ==
          0.0) ||
        !are_usable_sizes(box.half_extents))
        return false;
    // |R^T R - I| and |det R - 1| within half of rotation_tolerance here are surely within it in
    // rotation_problem's own arithmetic (the two differ by a few ulps); nearer the limit, it decides.
    double worst = 0.0;
    for (int i = 0; i < 3; ++i)
        for (int j = i; j < 3; ++j) {
            const double dot = r(0, i) * r(0, j) + r(1, i) * r(1, j) + r(2, i) * r(2, j);
            worst = std::max(worst, std::abs(dot - (i == j ? 1.0 : 0.0)));
        }
    const double det = r(0, 0) * (r(1, 1) * r(2, 2) - r(1, 2) * r(2, 1)) - r(0, 1) * (r(1, 0) * r(2, 2) - r(1, 2) * r(2, 0)) +
                       r(0, 2) * (r(1, 0) * r(2, 1) - r(1, 1) * r(2, 0));
    if (worst <= 0.5 * rotation_tolerance && std::abs(det - 1.0) <= 0.5 * rotation_tolerance) return true;
    return rotation_problem(r).empty();
}

/// The inverse of volume_doubles for kind `type`: its numbers, little-endian from `p` on, constructed in place
/// in `out` (straight from the bytes, without an intermediate array: this runs for every record of a file).
/// Returns is_surely_usable of the volume, tested here where its type is known without a second dispatch.
bool set_volume_from_bytes(BvType type, const unsigned char* p, BoundingVolume& out) {
    auto number = [p](std::size_t at) { return std::bit_cast<double>(load_u64_le(p + 8 * at)); };
    auto vec = [&](std::size_t at) { return Vec3(number(at), number(at + 1), number(at + 2)); };
    switch (type) {
        case BvType::aabb: return is_surely_usable(out.emplace<Aabb>(Aabb{vec(0), vec(3)}));
        case BvType::obb: {
            Obb& box = out.emplace<Obb>();
            box.center = vec(0);
            for (int r = 0; r < 3; ++r)
                for (int c = 0; c < 3; ++c) box.rotation(r, c) = number(static_cast<std::size_t>(3 + 3 * r + c));
            box.half_extents = vec(12);
            return is_surely_usable(box);
        }
        case BvType::sphere: return is_surely_usable(out.emplace<Sphere>(Sphere{vec(0), number(3)}));
        case BvType::capsule: return is_surely_usable(out.emplace<Capsule>(Capsule{vec(0), vec(3), number(6)}));
    }
    return false;
}

std::size_t volume_record_size(const BoundingVolume& volume) { return 1 + 8 * binary_double_count[volume.index()]; }

/// Writes into a buffer sized in advance, so the writer allocates once.
class BinaryWriter {
public:
    explicit BinaryWriter(unsigned char* out) : out_(out) {}
    void u8(std::uint8_t v) { *out_++ = v; }
    void u32(std::uint32_t v) {
        store_u32_le(out_, v);
        out_ += 4;
    }
    void u64(std::uint64_t v) {
        store_u64_le(out_, v);
        out_ += 8;
    }
    void bytes(std::string_view v) {
        if (!v.empty()) std::memcpy(out_, v.data(), v.size());
        out_ += v.size();
    }
    void volume(const BoundingVolume& bv) {
        std::array<double, 15> numbers{};
        const std::size_t n = volume_doubles(bv, numbers);
        u8(static_cast<std::uint8_t>(bv.index()));
        for (std::size_t i = 0; i < n; ++i) u64(std::bit_cast<std::uint64_t>(numbers[i]));
    }

private:
    unsigned char* out_;
};

/// Bounds-checked reading: every read first checks the bytes left, and failures carry the offset.
class BinaryReader {
public:
    BinaryReader(const unsigned char* data, std::size_t end) : data_(data), end_(end) {}
    [[nodiscard]] std::size_t offset() const { return at_; }
    [[nodiscard]] std::size_t left() const { return end_ - at_; }
    [[nodiscard]] bool has(std::size_t n) const { return n <= left(); }
    std::uint8_t u8() { return data_[at_++]; }
    std::uint32_t u32() {
        const std::uint32_t v = load_u32_le(data_ + at_);
        at_ += 4;
        return v;
    }
    std::uint64_t u64() {
        const std::uint64_t v = load_u64_le(data_ + at_);
        at_ += 8;
        return v;
    }
    std::string_view bytes(std::size_t n) {
        const std::string_view v(reinterpret_cast<const char*>(data_ + at_), n);
        at_ += n;
        return v;
    }
    /// A kind byte and its numbers, or the problem (unknown kind, record past the end) in `problem`. `usable`
    /// becomes false unless the volume passes is_surely_usable (and is left alone if it does).
    bool volume(BoundingVolume& out, std::string& problem, bool& usable) {
        if (!has(1)) return (problem = "the file ends inside a volume record"), false;
        const std::uint8_t kind = u8();
        if (kind >= bv_type_count) {
            --at_;
            problem = "unknown volume kind " + std::to_string(kind) + " (expected 0 aabb, 1 obb, 2 sphere or 3 capsule)";
            return false;
        }
        const std::size_t n = binary_double_count[kind];
        if (!has(8 * n)) return (problem = "the file ends inside a volume record"), false;
        if (!set_volume_from_bytes(static_cast<BvType>(kind), data_ + at_, out)) usable = false;
        at_ += 8 * n;
        return true;
    }
    /// Skips one volume record whose kind is known to be valid (the records were parsed once already).
    void skip_volume() { at_ += 1 + 8 * binary_double_count[data_[at_]]; }
    void skip(std::size_t n) { at_ += n; }

private:
    const unsigned char* data_;
    std::size_t end_;
    std::size_t at_ = 0;
};

/// The index K of a check's message that starts "<word> K", or -1.
long long leading_index(const std::string& message, std::string_view word) {
    if (message.size() <= word.size() + 1 || message.compare(0, word.size(), word) != 0 || message[word.size()] != ' ')
        return -1;
    unsigned long long index = 0;
    const char* first = message.data() + word.size() + 1;
    const auto [end, error] = std::from_chars(first, message.data() + message.size(), index);
    if (error != std::errc{} || end == first) return -1;
    return static_cast<long long>(index);
}



/// True when every byte of `text` is ASCII other than NUL: the common name, which then needs no UTF-8 decoding.
bool is_plain_ascii(std::string_view text) {
    for (const char c : text)
        if (static_cast<unsigned char>(c) - 1u >= 0x7Fu) return false;
    return true;
}

/// What one decoding task found: a problem and its offset (empty when its records parsed), and whether every
/// record also passed the on-the-fly checks of read_binary's stage 3.
struct DecodeOutcome {
    std::string problem;
    std::size_t problem_at = 0;
    bool sound = true;
    std::size_t records_at = 0;  ///< Where the task's records start (for stage 4's offsets).
};

/// The node records (they follow the header) handed to `nodes`, with check_structure()'s tests made on the way;
/// where `leaf_at` is given, the offset of each primitive's leaf record goes into it (for leaves_match_primitives).
DecodeOutcome decode_node_records(const unsigned char* data, std::size_t end, std::uint64_t node_count,
                                  std::uint64_t primitive_count, detail::BinaryNodeSink& nodes,
                                  std::vector<std::uint64_t>* leaf_at) {
    DecodeOutcome outcome;
    outcome.records_at = binary_header_size;
    BinaryReader reader(data, end);
    reader.skip(binary_header_size);
    auto fail = [&](std::size_t at, std::string problem) {
        outcome.problem = std::move(problem);
        outcome.problem_at = at;
        return outcome;
    };
    bool& sound = outcome.sound;
    std::uint64_t next_child = 1;  // breadth-first: inner nodes' child ranges follow each other from node 1 on
    std::uint64_t leaf_count = 0;
    std::vector<std::uint64_t> in_a_leaf(node_count == 0 ? 0 : (primitive_count + 63) / 64);  // one bit per primitive
    std::string problem;
    for (std::uint64_t i = 0; i < node_count; ++i) {
        const std::size_t at = reader.offset();
        // Decoded on the stack and handed over whole: a Bvh's emplace_back() would first clear the node in the
        // (fresh, uncached) array and then write it again.
        Node node;
        if (!reader.volume(node.volume, problem, sound)) return fail(reader.offset(), problem);
        if (!reader.has(binary_node_links_size)) return fail(at, "the file ends inside a node record");
        node.first_child = reader.u32();
        node.child_count = reader.u32();
        node.primitive = reader.u32();
        nodes.add(node);
        if (!sound) continue;
        if (node.is_leaf()) {
            // In range and in no other leaf; with as many leaves as primitives, that is each one once.
            const std::uint64_t bit = std::uint64_t{1} << (node.primitive % 64);
            sound = node.primitive < primitive_count && (in_a_leaf[node.primitive / 64] & bit) == 0;
            if (sound) in_a_leaf[node.primitive / 64] |= bit;
            if (sound && leaf_at != nullptr) (*leaf_at)[node.primitive] = at;
            ++leaf_count;
        } else {
            sound = node.child_count >= 2 && node.first_child == next_child &&
                    std::uint64_t{node.first_child} + node.child_count <= node_count;
            next_child += node.child_count;
        }
    }
    sound = sound && (node_count == 0 || (next_child == node_count && leaf_count == primitive_count));
    return outcome;
}

/// Where the primitive records start: after `node_count` node records from the header on, skipped by their kind
/// bytes alone; 0 and a `problem` when a record cannot be skipped (decode_node_records finds it as well, and its
/// report, with the offset, is the one returned). A loop of its own, the position in a register and the record
/// length computed rather than looked up, the file read ahead: it is one chain of dependent loads, a million long
/// in a large file, and was a sixth of a 10^6-primitive load as BinaryReader calls.
std::size_t skip_node_records(const unsigned char* data, std::size_t end, std::uint64_t node_count, std::string& problem) {
    // binary_double_count, one byte per kind: a shift replaces the table load on the loop's dependency chain.
    constexpr std::uint32_t packed_double_counts = [] {
        std::uint32_t packed = 0;
        for (std::size_t kind = 0; kind < bv_type_count; ++kind)
            packed |= static_cast<std::uint32_t>(binary_double_count[kind]) << (8 * kind);
        return packed;
    }();
    std::size_t at = binary_header_size;
    for (std::uint64_t i = 0; i < node_count; ++i) {
        if (at >= end) return (problem = "the file ends inside a node record"), 0;
        __builtin_prefetch(data + at + 2048);  // a hint only: it never faults, past the end or not
        const unsigned kind = data[at];
        if (kind >= bv_type_count) return (problem = "unknown volume kind " + std::to_string(kind)), 0;
        at += 1 + 8 * ((packed_double_counts >> (8 * kind)) & 0xFFu) + binary_node_links_size;
    }
    if (at > end) return (problem = "the file ends inside a node record"), 0;
    return at;
}

/// The primitive records and their names into `primitives` (or, when it is null, only read), with
/// validate_primitives()'s tests made on the way.
DecodeOutcome decode_primitive_records(const unsigned char* data, std::size_t end, std::uint64_t node_count,
                                       std::uint64_t primitive_count, std::vector<Primitive>* primitives) {
    DecodeOutcome outcome;
    auto fail = [&](std::size_t at, std::string problem) {
        outcome.problem = std::move(problem);
        outcome.problem_at = at;
        return outcome;
    };
    std::string problem;
    outcome.records_at = skip_node_records(data, end, node_count, problem);
    if (outcome.records_at == 0) return fail(binary_header_size, problem);
    BinaryReader reader(data, end);
    reader.skip(outcome.records_at);
    // The volumes first, then the names, which follow all primitive records: a bad record is named before any
    // name is read. An empty name (the usual case in a large generated set) leaves the array untouched, so the
    // second pass is one 4-byte read per primitive; a set with names walks its array twice.
    for (std::uint64_t i = 0; i < primitive_count; ++i) {
        BoundingVolume volume;  // on the stack, then appended whole (as for the nodes)
        if (!reader.volume(volume, problem, outcome.sound)) return fail(reader.offset(), problem);
        if (primitives != nullptr) primitives->emplace_back(volume, std::string());
    }
    for (std::uint64_t i = 0; i < primitive_count; ++i) {
        if (!reader.has(4)) return fail(reader.offset(), "the file ends inside the names");
        const std::uint32_t length = reader.u32();
        if (length == 0) continue;
        if (!reader.has(length))
            return fail(reader.offset() - 4, "a name of " + std::to_string(length) + " bytes runs past the end of the file");
        const std::size_t name_at = reader.offset();
        const std::string_view name = reader.bytes(length);
        std::size_t bad_at = 0;
        if (!is_plain_ascii(name))
            if (std::string bad = detail::utf8_problem(name, bad_at); !bad.empty()) return fail(name_at + bad_at, bad);
        if (primitives != nullptr) (*primitives)[i].name.assign(name);
    }
    if (reader.left() != 0)
        return fail(reader.offset(), std::to_string(reader.left()) + " unused bytes between the names and the checksum");
    return outcome;
}

/// Whether every primitive record's volume is, byte for byte, its leaf record's (`leaf_at`, from a sound node
/// pass): check_structure() requires a leaf to be its primitive, and a file stores both. One walk over the
/// primitive records (from `records_at`), each compared with its leaf's bytes.
bool leaves_match_primitives(const unsigned char* data, std::size_t end, std::size_t records_at,
                             std::uint64_t primitive_count, const std::vector<std::uint64_t>& leaf_at) {
    BinaryReader reader(data, end);
    reader.skip(records_at);
    for (std::uint64_t p = 0; p < primitive_count; ++p) {
        const std::size_t at = reader.offset();
        reader.skip_volume();
        const std::size_t length = reader.offset() - at;
        // The leaf's record holds its volume (kind byte first, so equal bytes mean the same kind) then its links.
        if (leaf_at[p] + length > end || std::memcmp(data + at, data + leaf_at[p], length) != 0) return false;
    }
    return true;
}

}  // namespace

bool has_binary_magic(std::span<const std::byte> bytes) {
    return bytes.size() >= binary_magic.size() &&
           std::memcmp(bytes.data(), binary_magic.data(), binary_magic.size()) == 0;
}

std::string write_binary(const Bvh& bvh) {
    // Stage 1: the exact size, so that the buffer is allocated once.
    // A name that is no UTF-8 (or holds a NUL) is written repaired, as the reader accepts only UTF-8 (utf8_name):
    // such a file could not be read back.
    std::vector<std::string> repaired_names;
    std::vector<std::uint32_t> repaired_at;
    for (std::uint32_t i = 0; i < bvh.primitives.size(); ++i) {
        std::size_t bad_at = 0;
        if (const std::string& name = bvh.primitives[i].name;
            !is_plain_ascii(name) && !detail::utf8_problem(name, bad_at).empty()) {
            repaired_names.push_back(detail::utf8_name(name));
            repaired_at.push_back(i);
        }
    }
    std::size_t size = binary_header_size + binary_checksum_size;
    for (const Node& node : bvh.nodes) size += volume_record_size(node.volume) + binary_node_links_size;
    for (const Primitive& primitive : bvh.primitives) size += volume_record_size(primitive.volume) + 4 + primitive.name.size();
    for (std::size_t k = 0; k < repaired_at.size(); ++k)
        size = size - bvh.primitives[repaired_at[k]].name.size() + repaired_names[k].size();
    std::string out;
    detail::resize_on_huge_pages(out, size);
    auto* data = reinterpret_cast<unsigned char*>(out.data());
    BinaryWriter writer(data);

    // Stage 2: header, nodes, primitives, names; field by field, little-endian.
    for (unsigned char c : binary_magic) writer.u8(c);
    writer.u32(binary_format_version);
    writer.u32(0);  // flags, reserved
    writer.u64(size);
    writer.u64(bvh.nodes.size());
    writer.u64(bvh.primitives.size());
    for (const Node& node : bvh.nodes) {
        writer.volume(node.volume);
        writer.u32(node.first_child);
        writer.u32(node.child_count);
        writer.u32(node.primitive);
    }
    for (const Primitive& primitive : bvh.primitives) writer.volume(primitive.volume);
    std::size_t next_repaired = 0;
    for (std::uint32_t i = 0; i < bvh.primitives.size(); ++i) {
        const bool repaired = next_repaired < repaired_at.size() && repaired_at[next_repaired] == i;
        const std::string& name = repaired ? repaired_names[next_repaired++] : bvh.primitives[i].name;
        writer.u32(static_cast<std::uint32_t>(name.size()));
        writer.bytes(name);
    }

    // Stage 3: the checksum over everything before it.
    const std::uint64_t crc = crc64_xz(std::as_bytes(std::span(out.data(), size - binary_checksum_size)));
    writer.u64(crc);
    return out;
}

namespace detail {

Result<DecodedBinary> decode_binary(std::span<const std::byte> bytes, const std::string& file,
                                   std::span<BinaryNodeSink* const> node_sinks, std::vector<Primitive>* primitives) {
    auto fail = [&](std::size_t offset, const std::string& problem) -> Result<DecodedBinary> {
        return Error{"offset " + std::to_string(offset) + ": " + problem, file};
    };
    const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
    const std::size_t size = bytes.size();

    // Stage 1: magic, version, reserved flags, the declared size, the checksum. In this order, so that a
    // file of another kind or version is named as such rather than as corrupted.
    if (size == 0) return fail(0, "file is empty");
    if (std::memcmp(data, binary_magic.data(), std::min(size, binary_magic.size())) != 0)
        return fail(0, "not an .hbvh file (wrong magic bytes)");
    if (size < binary_header_size)
        return fail(size, "file is truncated: it ends inside the " + std::to_string(binary_header_size) + "-byte header");
    BinaryReader header(data, size);
    header.skip(binary_magic.size());
    const std::uint32_t version = header.u32();
    if (version != binary_format_version)
        return fail(8, "format version " + std::to_string(version) + " is not supported (this reader reads version " +
                           std::to_string(binary_format_version) + ")");
    if (const std::uint32_t flags = header.u32(); flags != 0)
        return fail(12, "reserved flags are " + std::to_string(flags) + ", expected 0");
    const std::uint64_t declared_size = header.u64();
    if (declared_size > size)
        return fail(size, "file is truncated: the header says " + std::to_string(declared_size) + " bytes, the file has " +
                              std::to_string(size));
    if (declared_size < size)
        return fail(declared_size, std::to_string(size - declared_size) + " bytes after the end of the file (" +
                                       std::to_string(declared_size) + " bytes, says the header)");
    // A whole header, then fewer than the checksum's bytes, all of them declared: a header that is wrong.
    if (size < binary_header_size + binary_checksum_size)
        return fail(16, "the header says the file has " + std::to_string(declared_size) + " bytes, fewer than its " +
                            std::to_string(binary_header_size) + "-byte header and " +
                            std::to_string(binary_checksum_size) + "-byte checksum");
    const std::size_t checksum_at = size - binary_checksum_size;
    auto checksum_problem = [&]() -> std::string {
        const std::uint64_t stored = load_u64_le(data + checksum_at);
        const std::uint64_t computed = crc64_xz(bytes.first(checksum_at));
        if (stored == computed) return {};
        char text[64];
        std::snprintf(text, sizeof text, "stored %016llx, computed %016llx", static_cast<unsigned long long>(stored),
                      static_cast<unsigned long long>(computed));
        return std::string("checksum mismatch (CRC-64/XZ ") + text + "): the file is corrupted";
    };

    // Stage 2: counts against the bytes that hold them, before any allocation. A corrupted file is named as
    // such first, so a problem found here is reported only once the checksum has passed.
    const std::uint64_t node_count = header.u64();
    const std::uint64_t primitive_count = header.u64();
    const std::size_t body = checksum_at - binary_header_size;
    std::size_t count_problem_at = 0;
    std::string count_problem;
    if (node_count > body / binary_min_node_size) {
        count_problem_at = 24;
        count_problem = "node count " + std::to_string(node_count) + " is more than the " + std::to_string(body) +
                        " bytes of records can hold";
    } else if (node_count >= UINT32_MAX) {
        count_problem_at = 24;
        count_problem = "node count " + std::to_string(node_count) + " exceeds 32-bit indices";
    } else if (const std::size_t after_nodes = body - node_count * binary_min_node_size;
               primitive_count > after_nodes / binary_min_primitive_size) {
        count_problem_at = 32;
        count_problem = "primitive count " + std::to_string(primitive_count) + " is more than the " +
                        std::to_string(after_nodes) + " bytes left after the nodes can hold";
    } else if (primitive_count == 0) {
        count_problem_at = 32;
        count_problem = "the file holds no primitives";
    }

    // Stage 3: the records, each read bounds-checked. Alongside, everything check_structure() (or, for a
    // primitive set, validate_primitives()) would check is tested on the fly without composing messages;
    // `sound` stays true only if all of it passed, and then stage 4 has nothing left to find.
    //
    // In a large file the checksum, each sink's pass over the nodes and the primitives are tasks of their own,
    // run at once on the cores there are (filling the 300 MB of a 10^6-primitive tree is most of a load, and one
    // core alone leaves half the machine idle). Each output is written by one task only, front to back, so the
    // result does not depend on the thread count, and the problem reported is the one a reader going front to
    // back finds first: a checksum mismatch, then the counts, then the first bad node record, then the first
    // bad primitive record (every pass over the nodes reads the same bytes; the first one's findings are
    // kept). Before the checksum is known the counts are only known to be possible for the file's size, which
    // bounds what is allocated.
    constexpr std::size_t concurrent_decode_bytes = std::size_t{1} << 19;  // below, a second task costs more than it saves
    const bool concurrent = size >= concurrent_decode_bytes && count_problem.empty();
    std::string corrupted;
    if (!concurrent) {
        if (corrupted = checksum_problem(); !corrupted.empty()) return fail(checksum_at, corrupted);
        if (!count_problem.empty()) return fail(count_problem_at, count_problem);
    }
    std::vector<DecodeOutcome> node_outcomes(node_sinks.size());
    DecodeOutcome primitives_outcome;
    std::vector<std::uint64_t> leaf_at;  // filled by the first node pass, for leaves_match_primitives
    auto decode_nodes = [&](std::size_t pass) {
        node_sinks[pass]->reserve(node_count, primitive_count);
        if (pass == 0 && node_count > 0 && count_problem.empty()) {
            detail::reserve_on_huge_pages(leaf_at, primitive_count);
            leaf_at.resize(primitive_count);
        }
        node_outcomes[pass] = decode_node_records(data, checksum_at, node_count, primitive_count, *node_sinks[pass],
                                                  pass == 0 && !leaf_at.empty() ? &leaf_at : nullptr);
    };
    auto decode_primitives = [&] {
        if (primitives != nullptr) detail::reserve_on_huge_pages(*primitives, primitive_count);
        primitives_outcome = decode_primitive_records(data, checksum_at, node_count, primitive_count, primitives);
    };
    if (concurrent) {
        tbb::task_group tasks;
        for (std::size_t pass = 0; pass < node_sinks.size(); ++pass) tasks.run([&, pass] { decode_nodes(pass); });
        tasks.run(decode_primitives);
        corrupted = checksum_problem();
        tasks.wait();
    } else {
        for (std::size_t pass = 0; pass < node_sinks.size(); ++pass) decode_nodes(pass);
        if (node_outcomes.empty() || node_outcomes.front().problem.empty()) decode_primitives();
    }
    const DecodeOutcome nodes_outcome = node_outcomes.empty() ? DecodeOutcome{} : node_outcomes.front();
    if (!corrupted.empty()) return fail(checksum_at, corrupted);
    if (!nodes_outcome.problem.empty()) return fail(nodes_outcome.problem_at, nodes_outcome.problem);
    if (!primitives_outcome.problem.empty()) return fail(primitives_outcome.problem_at, primitives_outcome.problem);
    DecodedBinary decoded;
    decoded.node_count = node_count;
    decoded.primitive_count = primitive_count;
    decoded.sound = nodes_outcome.sound && primitives_outcome.sound;
    decoded.primitives_at = primitives_outcome.records_at;
    // A sound node pass put every primitive in one leaf; the leaf must also be that primitive (stage 4's
    // check_structure names the first that is not).
    if (decoded.sound && node_count > 0)
        decoded.sound = leaves_match_primitives(data, checksum_at, decoded.primitives_at, primitive_count, leaf_at);
    return decoded;
}

}  // namespace detail

Result<Bvh> read_binary(std::span<const std::byte> bytes, std::string_view source_name) {
    const std::string file(source_name);
    // The nodes appended to the Bvh as decoded (reserve and append rather than resize: the large array is
    // then written once, not zeroed first).
    class IntoBvh final : public detail::BinaryNodeSink {
    public:
        explicit IntoBvh(std::vector<Node>& nodes) : nodes_(nodes) {}
        void reserve(std::uint64_t node_count, std::uint64_t /*primitive_count*/) override {
            detail::reserve_on_huge_pages(nodes_, node_count);
        }
        void add(const Node& node) override { nodes_.push_back(node); }

    private:
        std::vector<Node>& nodes_;
    };
    Bvh bvh;
    IntoBvh sink(bvh.nodes);
    detail::BinaryNodeSink* const sinks[] = {&sink};
    const Result<detail::DecodedBinary> decoded = detail::decode_binary(bytes, file, sinks, &bvh.primitives);
    if (!decoded) return decoded.error();
    if (decoded->sound) return bvh;

    // Stage 4: something failed on the way, so run the same checks as for any other hierarchy, for their
    // words. Their messages name a node or primitive; the offset of its record is found by walking the
    // (already parsed, so well-formed) records again.
    const Status checked = bvh.nodes.empty() ? validate_primitives(bvh.primitives) : check_structure(bvh);
    if (!checked) {
        const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
        const std::size_t checksum_at = bytes.size() - binary_checksum_size;
        const std::string& message = checked.error().message;
        std::size_t offset = binary_header_size;
        if (const long long node = leading_index(message, "node");
            node >= 0 && static_cast<std::uint64_t>(node) < decoded->node_count) {
            BinaryReader walk(data, checksum_at);
            walk.skip(binary_header_size);
            for (long long i = 0; i < node; ++i) {
                walk.skip_volume();
                walk.skip(binary_node_links_size);
            }
            offset = walk.offset();
        } else if (const long long primitive = leading_index(message, "primitive");
                   primitive >= 0 && static_cast<std::uint64_t>(primitive) < decoded->primitive_count) {
            BinaryReader walk(data, checksum_at);
            walk.skip(decoded->primitives_at);
            for (long long i = 0; i < primitive; ++i) walk.skip_volume();
            offset = walk.offset();
        }
        return Error{"offset " + std::to_string(offset) + ": " + message, file};
    }
    return bvh;
}

}  // namespace hbvh
