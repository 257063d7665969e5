// SPDX-License-Identifier: MIT
// The PLY header check (ply_header.hpp). Grammar: Paul Bourke's PLY 1.0 description, as assimp 5.2 reads it.
#include "ply_header.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdint>
#include <fstream>
#include <istream>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "hbvh/io/file.hpp"

namespace hbvh::detail {
namespace {

constexpr std::array<std::string_view, 16> scalar_types{"char",  "uchar", "short",  "ushort", "int",   "uint",
                                                         "float", "double", "int8", "uint8",  "int16", "uint16",
                                                         "int32", "uint32", "float32", "float64"};

bool is_scalar_type(std::string_view word) {
    return std::find(scalar_types.begin(), scalar_types.end(), word) != scalar_types.end();
}

/// A header line's words, split at spaces and tabs only (assimp also splits at other control characters, which
/// is how "end_header\v..." hid a body in the header line).
std::vector<std::string> words_of(std::string_view line) {
    std::vector<std::string> words;
    std::size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
        const std::size_t start = i;
        while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
        if (i > start) words.emplace_back(line.substr(start, i - start));
    }
    return words;
}

/// True when every byte of the line is printable ASCII, a space or a tab.
bool is_plain_text(std::string_view line) {
    return std::all_of(line.begin(), line.end(), [](char c) {
        const auto byte = static_cast<unsigned char>(c);
        return c == '\t' || (byte >= 0x20 && byte < 0x7f);
    });
}

/// True for a name that starts with a letter or '_' and goes on with letters, digits, '_', '-' or '.'. assimp reads
/// a name that starts with digits partly as a number ("element 2222...2222face 1" made it allocate 57 GB, found
/// by fuzzing), and no PLY writer names elements or properties that way.
bool is_name(std::string_view word) {
    const auto is_letter = [](char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; };
    if (word.empty() || !is_letter(word.front())) return false;
    return std::all_of(word.begin(), word.end(),
                       [&](char c) { return is_letter(c) || (c >= '0' && c <= '9') || c == '-' || c == '.'; });
}

/// The count of an element line: decimal digits only, saturated instead of overflowing (assimp reads overlong
/// numbers too; the size check then refuses the file).
bool parse_count(std::string_view text, std::uint64_t saturated, std::uint64_t& count) {
    if (text.empty()) return false;
    count = 0;
    for (const char digit : text) {
        if (digit < '0' || digit > '9') return false;
        count = std::min(saturated, count * 10 + static_cast<std::uint64_t>(digit - '0'));
    }
    return true;
}

/// True when the first bytes that are neither whitespace nor control characters spell "ply" in any case.
bool starts_like_ply(std::istream& stream) {
    char c = 0;
    while (stream.get(c) && (static_cast<unsigned char>(c) <= 0x20 || c == 0x7f)) continue;
    std::string magic(1, c);
    for (int i = 0; i < 2 && stream.get(c); ++i) magic += c;
    for (char& m : magic) m = static_cast<char>(std::tolower(static_cast<unsigned char>(m)));
    return magic == "ply";
}

}  // namespace

Status check_ply_header(const std::string& path) {
    std::ifstream stream(path, std::ios::binary);
    // assimp reads a file as PLY when it is named .ply, and otherwise when it starts with "ply" in any case, even
    // after leading control bytes ("plY", "\nply" and "\0\0\0\5\nply" all hung it, found by fuzzing). Every such
    // file must be proper PLY, whose first line is "ply".
    if (lower_case_extension(path) != ".ply" && !starts_like_ply(stream)) return Ok{};
    stream.clear();
    stream.seekg(0, std::ios::end);
    const auto file_size = static_cast<std::uint64_t>(stream.tellg());
    stream.seekg(0);

    // Every element instance takes at least one byte per property (one byte for a property-less element), in
    // ASCII and binary alike, so a header that declares more than the rest of the file holds is refused:
    // "element vertex 99999999999" in an 80-byte file made assimp loop and allocate for minutes.
    constexpr std::uint64_t saturated = std::numeric_limits<std::uint64_t>::max() / 2;
    std::uint64_t needed = 0;          // Bytes the declared elements take at least.
    std::uint64_t element_count = 0;   // Instances of the element being declared.
    std::uint64_t property_count = 0;  // Its properties so far.
    bool in_element = false;
    auto close_element = [&] {
        if (!in_element) return;
        const std::uint64_t per_instance = std::max<std::uint64_t>(1, property_count);
        const bool overflows = element_count > (saturated - needed) / per_instance;
        needed = overflows ? saturated : needed + element_count * per_instance;
    };
    auto malformed = [&](int line_number, const std::string& problem) {
        return Error("malformed PLY header: " + problem, path, line_number);
    };

    std::string line;
    int line_number = 0;
    while (std::getline(stream, line)) {
        ++line_number;
        if (!line.empty() && line.back() == '\r') line.pop_back();  // CRLF files
        const std::vector<std::string> words = words_of(line);
        const std::string keyword = words.empty() ? std::string() : words.front();
        // assimp reads the magic and the format as the first two lines, whatever else they hold.
        if (line_number == 1) {
            if (line != "ply") return malformed(line_number, "the first line must be exactly \"ply\"");
            continue;
        }
        if (line_number == 2) {
            const bool known = words.size() == 3 && words[0] == "format" &&
                               (words[1] == "ascii" || words[1] == "binary_little_endian" ||
                                words[1] == "binary_big_endian");
            if (!known || !is_plain_text(line))
                return malformed(line_number, "the second line must be \"format ascii|binary_little_endian|"
                                              "binary_big_endian VERSION\"");
            continue;
        }
        // Comments are free text: any bytes but line breaks.
        if (keyword == "comment" || keyword == "obj_info") continue;
        if (!is_plain_text(line)) return malformed(line_number, "a control or non-ASCII byte outside a comment");
        if (keyword == "element") {
            close_element();
            if (words.size() != 3 || !is_name(words[1]) || !parse_count(words[2], saturated, element_count))
                return malformed(line_number, "expected \"element NAME COUNT\"");
            property_count = 0;
            in_element = true;
        } else if (keyword == "property") {
            if (!in_element) return malformed(line_number, "a property before any element");
            const bool scalar = words.size() == 3 && is_scalar_type(words[1]) && is_name(words[2]);
            const bool list = words.size() == 5 && words[1] == "list" && is_scalar_type(words[2]) &&
                              is_scalar_type(words[3]) && is_name(words[4]);
            if (!scalar && !list)
                return malformed(line_number, "expected \"property TYPE NAME\" or \"property list TYPE TYPE NAME\"");
            ++property_count;
        } else if (keyword == "end_header") {
            if (words.size() != 1) return malformed(line_number, "end_header must stand alone on its line");
            close_element();
            const auto header_end = static_cast<std::uint64_t>(stream.tellg());
            const std::uint64_t body = stream.eof() || header_end > file_size ? 0 : file_size - header_end;
            if (needed > body)
                return Error("PLY header declares elements needing at least " + std::to_string(needed) +
                                 " bytes, but only " + std::to_string(body) + " follow the header",
                             path, line_number);
            return Ok{};
        } else if (!keyword.empty()) {
            return malformed(line_number, "unknown keyword \"" + keyword + "\"");
        }
    }
    if (line_number == 0) return Error("empty PLY file", path);
    // assimp 5.2 never stops looking for the end of such a header.
    return Error("PLY header has no end_header line", path, line_number);
}

}  // namespace hbvh::detail
