// SPDX-License-Identifier: MIT
// The .hbvh binary format (docs/formats.md, "The binary format"): explicit little-endian fields, CRC-64/XZ.
#include "hbvh/tree/binary_format.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <system_error>
#include <vector>

#include "hbvh/geometry/validation.hpp"
#include "hbvh/tree/validate.hpp"

namespace hbvh {
namespace {

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

// CRC-64/XZ by slicing-by-8 (Kounavis & Berry's table method): eight tables let the loop fold 8 input bytes
// per step instead of one, which makes the checksum a small part of the load time of a big file.
constexpr std::uint64_t crc64_reflected_polynomial = 0xC96C5795D7870F42ULL;  // 0x42F0E1EBA9EA3693 bit-reversed

using Crc64Tables = std::array<std::array<std::uint64_t, 256>, 8>;
constexpr Crc64Tables make_crc64_tables() {
    Crc64Tables tables{};
    for (std::uint64_t i = 0; i < 256; ++i) {
        std::uint64_t crc = i;
        for (int bit = 0; bit < 8; ++bit) crc = (crc & 1) != 0 ? (crc >> 1) ^ crc64_reflected_polynomial : crc >> 1;
        tables[0][i] = crc;
    }
    // tables[k][i]: the CRC of byte i followed by k zero bytes.
    for (std::size_t k = 1; k < 8; ++k)
        for (std::size_t i = 0; i < 256; ++i)
            tables[k][i] = (tables[k - 1][i] >> 8) ^ tables[0][tables[k - 1][i] & 0xFF];
    return tables;
}
constexpr Crc64Tables crc64_tables = make_crc64_tables();

std::uint64_t load_u64_le(const unsigned char* p) {
    std::uint64_t value = 0;
    for (int i = 7; i >= 0; --i) value = (value << 8) | p[i];
    return value;
}
std::uint32_t load_u32_le(const unsigned char* p) {
    return std::uint32_t{p[0]} | std::uint32_t{p[1]} << 8 | std::uint32_t{p[2]} << 16 | std::uint32_t{p[3]} << 24;
}
void store_u64_le(unsigned char* p, std::uint64_t value) {
    for (int i = 0; i < 8; ++i) p[i] = static_cast<unsigned char>(value >> (8 * i));
}
void store_u32_le(unsigned char* p, std::uint32_t value) {
    for (int i = 0; i < 4; ++i) p[i] = static_cast<unsigned char>(value >> (8 * i));
}

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

/// The inverse of volume_doubles for kind `type` (numbers in file order), constructed in place in `out`.
void set_volume_from_doubles(BvType type, const double* d, BoundingVolume& out) {
    auto vec = [&](std::size_t at) { return Vec3(d[at], d[at + 1], d[at + 2]); };
    switch (type) {
        case BvType::aabb: out.emplace<Aabb>(Aabb{vec(0), vec(3)}); return;
        case BvType::obb: {
            Obb& box = out.emplace<Obb>();
            box.center = vec(0);
            for (int r = 0; r < 3; ++r)
                for (int c = 0; c < 3; ++c) box.rotation(r, c) = d[3 + 3 * r + c];
            box.half_extents = vec(12);
            return;
        }
        case BvType::sphere: out.emplace<Sphere>(Sphere{vec(0), d[3]}); return;
        case BvType::capsule: out.emplace<Capsule>(Capsule{vec(0), vec(3), d[6]}); return;
    }
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
    /// A kind byte and its numbers, or the problem (unknown kind, record past the end) in `problem`.
    bool volume(BoundingVolume& out, std::string& problem) {
        if (!has(1)) return (problem = "the file ends inside a volume record"), false;
        const std::uint8_t kind = u8();
        if (kind >= bv_type_count) {
            --at_;
            problem = "unknown volume kind " + std::to_string(kind) + " (expected 0 aabb, 1 obb, 2 sphere or 3 capsule)";
            return false;
        }
        const std::size_t n = binary_double_count[kind];
        if (!has(8 * n)) return (problem = "the file ends inside a volume record"), false;
        std::array<double, 15> numbers{};
        for (std::size_t i = 0; i < n; ++i) numbers[i] = std::bit_cast<double>(u64());
        set_volume_from_doubles(static_cast<BvType>(kind), numbers.data(), out);
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

/// Empty when `text` is well-formed UTF-8 (no overlong forms, no surrogates, nothing above U+10FFFF) without
/// NUL; else the problem and, in `bad_at`, the offset of the offending byte within `text`.
std::string utf8_problem(std::string_view text, std::size_t& bad_at) {
    const auto* s = reinterpret_cast<const unsigned char*>(text.data());
    const std::size_t n = text.size();
    for (std::size_t i = 0; i < n;) {
        bad_at = i;
        const unsigned char c = s[i];
        if (c == 0) return "a name holds a NUL byte";
        if (c < 0x80) {
            ++i;
            continue;
        }
        std::size_t length = 0;
        std::uint32_t code = 0, smallest = 0;
        if ((c & 0xE0) == 0xC0) length = 2, code = c & 0x1F, smallest = 0x80;
        else if ((c & 0xF0) == 0xE0) length = 3, code = c & 0x0F, smallest = 0x800;
        else if ((c & 0xF8) == 0xF0) length = 4, code = c & 0x07, smallest = 0x10000;
        else return "a name is not UTF-8 (byte 0x" + [&] {
            char hex[3];
            std::to_chars(hex, hex + 2, c, 16);
            hex[2] = 0;
            return std::string(hex);
        }() + " cannot start a character)";
        if (length > n - i) return "a name is not UTF-8 (a character is cut off at its end)";
        for (std::size_t k = 1; k < length; ++k) {
            if ((s[i + k] & 0xC0) != 0x80) return "a name is not UTF-8 (a character's continuation byte is missing)";
            code = (code << 6) | (s[i + k] & 0x3F);
        }
        if (code < smallest) return "a name is not UTF-8 (overlong encoding)";
        if (code > 0x10FFFF || (code >= 0xD800 && code <= 0xDFFF))
            return "a name is not UTF-8 (no Unicode character: surrogate or above U+10FFFF)";
        i += length;
    }
    return {};
}

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

std::string describe_errno(int code) { return std::generic_category().message(code); }

}  // namespace

std::uint64_t crc64_xz(std::span<const std::byte> bytes) {
    const auto* p = reinterpret_cast<const unsigned char*>(bytes.data());
    std::size_t n = bytes.size();
    std::uint64_t crc = ~std::uint64_t{0};
    const Crc64Tables& t = crc64_tables;
    for (; n >= 8; n -= 8, p += 8) {
        crc ^= load_u64_le(p);
        crc = t[7][crc & 0xFF] ^ t[6][(crc >> 8) & 0xFF] ^ t[5][(crc >> 16) & 0xFF] ^ t[4][(crc >> 24) & 0xFF] ^
              t[3][(crc >> 32) & 0xFF] ^ t[2][(crc >> 40) & 0xFF] ^ t[1][(crc >> 48) & 0xFF] ^ t[0][crc >> 56];
    }
    for (; n > 0; --n, ++p) crc = (crc >> 8) ^ t[0][(crc ^ *p) & 0xFF];
    return ~crc;
}

bool has_binary_magic(std::span<const std::byte> bytes) {
    return bytes.size() >= binary_magic.size() &&
           std::memcmp(bytes.data(), binary_magic.data(), binary_magic.size()) == 0;
}

std::string write_binary(const Bvh& bvh) {
    // Stage 1: the exact size, so that the buffer is allocated once.
    std::size_t size = binary_header_size + binary_checksum_size;
    for (const Node& node : bvh.nodes) size += volume_record_size(node.volume) + binary_node_links_size;
    for (const Primitive& primitive : bvh.primitives) size += volume_record_size(primitive.volume) + 4 + primitive.name.size();
    std::string out(size, '\0');
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
    for (const Primitive& primitive : bvh.primitives) {
        writer.u32(static_cast<std::uint32_t>(primitive.name.size()));
        writer.bytes(primitive.name);
    }

    // Stage 3: the checksum over everything before it.
    const std::uint64_t crc = crc64_xz(std::as_bytes(std::span(out.data(), size - binary_checksum_size)));
    writer.u64(crc);
    return out;
}

Result<Bvh> read_binary(std::span<const std::byte> bytes, std::string_view source_name) {
    const std::string file(source_name);
    auto fail = [&](std::size_t offset, const std::string& problem) -> Result<Bvh> {
        return Error{"offset " + std::to_string(offset) + ": " + problem, file};
    };
    const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
    const std::size_t size = bytes.size();

    // Stage 1: magic, version, reserved flags, the declared size, the checksum. In this order, so that a
    // file of another kind or version is named as such rather than as corrupted.
    if (size == 0) return fail(0, "file is empty");
    if (std::memcmp(data, binary_magic.data(), std::min(size, binary_magic.size())) != 0)
        return fail(0, "not an .hbvh file (wrong magic bytes)");
    if (size < binary_header_size + binary_checksum_size)
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
    const std::size_t checksum_at = size - binary_checksum_size;
    const std::uint64_t stored = load_u64_le(data + checksum_at);
    const std::uint64_t computed = crc64_xz(bytes.first(checksum_at));
    if (stored != computed) {
        char text[64];
        std::snprintf(text, sizeof text, "stored %016llx, computed %016llx", static_cast<unsigned long long>(stored),
                      static_cast<unsigned long long>(computed));
        return fail(checksum_at, std::string("checksum mismatch (CRC-64/XZ ") + text + "): the file is corrupted");
    }

    // Stage 2: counts against the bytes that hold them, before any allocation.
    const std::uint64_t node_count = header.u64();
    const std::uint64_t primitive_count = header.u64();
    const std::size_t body = checksum_at - binary_header_size;
    if (node_count > body / binary_min_node_size)
        return fail(24, "node count " + std::to_string(node_count) + " is more than the " + std::to_string(body) +
                            " bytes of records can hold");
    if (node_count >= UINT32_MAX) return fail(24, "node count " + std::to_string(node_count) + " exceeds 32-bit indices");
    const std::size_t after_nodes = body - node_count * binary_min_node_size;
    if (primitive_count > after_nodes / binary_min_primitive_size)
        return fail(32, "primitive count " + std::to_string(primitive_count) + " is more than the " +
                            std::to_string(after_nodes) + " bytes left after the nodes can hold");
    if (primitive_count == 0) return fail(32, "the file holds no primitives");

    // Stage 3: the records, each read bounds-checked.
    BinaryReader reader(data, checksum_at);
    reader.skip(binary_header_size);
    Bvh bvh;
    // reserve and append rather than resize: the (large) arrays are then written once, not zeroed first.
    bvh.nodes.reserve(node_count);
    bvh.primitives.reserve(primitive_count);
    std::string problem;
    for (std::uint64_t i = 0; i < node_count; ++i) {
        const std::size_t at = reader.offset();
        Node& node = bvh.nodes.emplace_back();
        if (!reader.volume(node.volume, problem)) return fail(reader.offset(), problem);
        if (!reader.has(binary_node_links_size)) return fail(at, "the file ends inside a node record");
        node.first_child = reader.u32();
        node.child_count = reader.u32();
        node.primitive = reader.u32();
    }
    const std::size_t primitives_at = reader.offset();
    for (std::uint64_t i = 0; i < primitive_count; ++i)
        if (!reader.volume(bvh.primitives.emplace_back().volume, problem)) return fail(reader.offset(), problem);
    for (Primitive& primitive : bvh.primitives) {
        if (!reader.has(4)) return fail(reader.offset(), "the file ends inside the names");
        const std::uint32_t length = reader.u32();
        if (!reader.has(length))
            return fail(reader.offset() - 4, "a name of " + std::to_string(length) + " bytes runs past the end of the file");
        const std::size_t name_at = reader.offset();
        primitive.name.assign(reader.bytes(length));
        std::size_t bad_at = 0;
        if (std::string bad = utf8_problem(primitive.name, bad_at); !bad.empty()) return fail(name_at + bad_at, bad);
    }
    if (reader.left() != 0)
        return fail(reader.offset(), std::to_string(reader.left()) + " unused bytes between the names and the checksum");

    // Stage 4: the same checks as any other hierarchy. Their messages name a node or primitive; the offset
    // of its record is found by walking the (already parsed, so well-formed) records again.
    const Status checked = bvh.nodes.empty() ? validate_primitives(bvh.primitives) : check_structure(bvh);
    if (!checked) {
        const std::string& message = checked.error().message;
        std::size_t offset = binary_header_size;
        if (const long long node = leading_index(message, "node"); node >= 0 && static_cast<std::uint64_t>(node) < node_count) {
            BinaryReader walk(data, checksum_at);
            walk.skip(binary_header_size);
            for (long long i = 0; i < node; ++i) {
                walk.skip_volume();
                walk.skip(binary_node_links_size);
            }
            offset = walk.offset();
        } else if (const long long primitive = leading_index(message, "primitive");
                   primitive >= 0 && static_cast<std::uint64_t>(primitive) < primitive_count) {
            BinaryReader walk(data, checksum_at);
            walk.skip(primitives_at);
            for (long long i = 0; i < primitive; ++i) walk.skip_volume();
            offset = walk.offset();
        }
        return fail(offset, message);
    }
    return bvh;
}

Result<Bvh> read_binary_file(const std::filesystem::path& path) {
    const std::string name = path.string();
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return Error{"cannot open for reading: " + describe_errno(errno), name};
    struct stat info {};
    std::vector<std::byte> bytes;
    int failure = 0;
    if (::fstat(fd, &info) != 0) failure = errno;
    else if (S_ISDIR(info.st_mode)) failure = EISDIR;
    else {
        // st_size is a hint (a pipe has none); read to the end whatever it says.
        bytes.resize(S_ISREG(info.st_mode) && info.st_size > 0 ? static_cast<std::size_t>(info.st_size) : 0);
        std::size_t filled = 0;
        for (;;) {
            if (filled == bytes.size()) bytes.resize(bytes.size() + 65536);
            const ssize_t got = ::read(fd, bytes.data() + filled, bytes.size() - filled);
            if (got < 0 && errno == EINTR) continue;
            if (got < 0) {
                failure = errno;
                break;
            }
            if (got == 0) break;
            filled += static_cast<std::size_t>(got);
        }
        bytes.resize(filled);
    }
    ::close(fd);
    if (failure != 0) return Error{"cannot read: " + describe_errno(failure), name};
    return read_binary(bytes, name);
}

Status write_binary_file(const std::filesystem::path& path, const Bvh& bvh) {
    const std::string name = path.string();
    if (path.empty() || !path.has_filename()) return Error{"not a file name", name};
    const std::string content = write_binary(bvh);
    // A hidden temporary next to the target (same file system, so rename() is atomic); O_EXCL never
    // opens someone else's file. The io library's write_file_atomic does the same; core cannot use it.
    static std::atomic<unsigned> counter{0};
    std::filesystem::path temporary;
    int fd = -1;
    for (unsigned attempt = 0; attempt < 100 && fd < 0; ++attempt) {
        std::string hidden(1, '.');
        hidden += path.filename().string();
        hidden += ".tmp-";
        hidden += std::to_string(::getpid());
        hidden += '-';
        hidden += std::to_string(counter.fetch_add(1));
        temporary = path.parent_path() / hidden;
        fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (fd < 0 && errno != EEXIST && errno != EINTR) break;
    }
    if (fd < 0) return Error{"cannot create a temporary file next to it: " + describe_errno(errno), name};
    auto fail = [&](const std::string& what, int code) -> Status {
        ::close(fd);
        ::unlink(temporary.c_str());
        return Error{what + ": " + describe_errno(code), name};
    };
    // An existing file keeps its permission bits.
    struct stat existing {};
    if (::stat(path.c_str(), &existing) == 0 && S_ISREG(existing.st_mode) && ::fchmod(fd, existing.st_mode & 07777) != 0)
        return fail("cannot set permissions", errno);
    for (std::string_view rest = content; !rest.empty();) {
        const ssize_t written = ::write(fd, rest.data(), rest.size());
        if (written < 0 && errno == EINTR) continue;
        if (written < 0) return fail("cannot write", errno);
        rest.remove_prefix(static_cast<std::size_t>(written));
    }
    if (::fsync(fd) != 0) return fail("cannot flush to disk", errno);
    if (::close(fd) != 0) {
        const int code = errno;
        ::unlink(temporary.c_str());
        return Error{"cannot write: " + describe_errno(code), name};
    }
    if (::rename(temporary.c_str(), path.c_str()) != 0) {
        const int code = errno;
        ::unlink(temporary.c_str());
        return Error{"cannot rename the temporary file over it: " + describe_errno(code), name};
    }
    return Ok{};
}

}  // namespace hbvh
