// SPDX-License-Identifier: MIT
#include "hbvh/fit/volume_policy.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <sstream>
#include <string>
#include <utility>

#include "hbvh/files.hpp"

namespace hbvh {
namespace {
/// Splits "a,b,c" into trimmed words; empty words are kept so that the caller can reject them.
std::vector<std::string_view> split_list(std::string_view list) {
    std::vector<std::string_view> words;
    std::size_t start = 0;
    while (true) {
        const std::size_t comma = list.find(',', start);
        std::string_view word = list.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start);
        while (!word.empty() && word.front() == ' ') word.remove_prefix(1);
        while (!word.empty() && word.back() == ' ') word.remove_suffix(1);
        words.push_back(word);
        if (comma == std::string_view::npos) break;
        start = comma + 1;
    }
    return words;
}

bool weight_in_range(double weight) { return weight >= min_type_weight && weight <= max_type_weight; }

std::string weight_range_text() { return "a weight must be a number from 1e-6 to 1e6 (they are ratios of test costs)"; }

/// Shortest text that reads back as `value` ("inf", "nan" for those).
std::string number_text(double value) {
    std::array<char, 32> text{};
    const auto [end, code] = std::to_chars(text.data(), text.data() + text.size(), value);
    return code == std::errc{} ? std::string(text.data(), end) : std::to_string(value);
}

/// parse_type_weights' work; `named` says which kinds earlier entries (of this list, or of earlier lines of a
/// file) have weighted, so that a kind named twice anywhere is refused.
Result<VolumePolicy> parse_weights_into(std::string_view list, VolumePolicy base, std::array<bool, bv_type_count>& named) {
    for (std::string_view entry : split_list(list)) {
        const std::size_t equals = entry.find('=');
        if (equals == std::string_view::npos)
            return Error{"type weight '" + std::string(entry) + "' is not of the form type=weight"};
        const std::optional<BvType> type = parse_bv_type(entry.substr(0, equals));
        if (!type) return Error{"unknown bounding-volume type in weight '" + std::string(entry) + "'"};
        const std::string_view number = entry.substr(equals + 1);
        double weight = 0.0;
        const auto [end, code] = std::from_chars(number.data(), number.data() + number.size(), weight);
        if (code != std::errc{} || end != number.data() + number.size() || !weight_in_range(weight))
            return Error{"type weight '" + std::string(entry) + "': " + weight_range_text()};
        // A kind named twice is a typo or two files pasted together; which one was meant cannot be told.
        if (std::exchange(named[static_cast<std::size_t>(*type)], true))
            return Error{"type weight '" + std::string(entry) + "': " + std::string(to_string(*type)) + " is weighted twice"};
        base.weight[static_cast<std::size_t>(*type)] = weight;
    }
    return base;
}
}  // namespace

VolumePolicy VolumePolicy::only(BvType type) {
    VolumePolicy policy;
    policy.allowed.fill(false);
    policy.allowed[static_cast<std::size_t>(type)] = true;
    return policy;
}

Result<VolumePolicy> parse_allowed_types(std::string_view list, VolumePolicy base) {
    base.allowed.fill(false);
    for (std::string_view word : split_list(list)) {
        const std::optional<BvType> type = parse_bv_type(word);
        if (!type)
            return Error{"unknown bounding-volume type '" + std::string(word) + "' (expected aabb, obb, sphere or capsule)"};
        base.allowed[static_cast<std::size_t>(*type)] = true;
    }
    return base;
}

Status validate_policy(const VolumePolicy& policy) {
    bool any = false;
    for (BvType type : all_bv_types) {
        if (!policy.is_allowed(type)) continue;
        any = true;
        const double weight = policy.weight_of(type);
        if (!weight_in_range(weight))
            return Error{"volume policy: the weight of " + std::string(to_string(type)) + " is " + number_text(weight) +
                         "; " + weight_range_text()};
    }
    if (!any) return Error{"volume policy: no BV kind is allowed; allow at least one of aabb, obb, sphere, capsule"};
    return Ok{};
}

Result<VolumePolicy> parse_type_weights(std::string_view list, VolumePolicy base) {
    std::array<bool, bv_type_count> named{};
    return parse_weights_into(list, base, named);
}

Result<VolumePolicy> read_type_weights_file(const std::filesystem::path& path, VolumePolicy base) {
    Result<std::string> text = read_text_file(path);
    if (!text) return text.error();
    // A byte order mark, entries on lines or separated by commas or blanks, as an editor may leave them, and
    // comments from a '#' to the end of its line.
    std::string_view content = *text;
    if (content.starts_with("\xEF\xBB\xBF")) content.remove_prefix(3);
    std::istringstream lines{std::string(content)};
    int line_number = 0;
    bool any = false;
    std::array<bool, bv_type_count> named{};
    for (std::string line; std::getline(lines, line);) {
        ++line_number;
        line.erase(std::min(line.find('#'), line.size()));
        std::replace(line.begin(), line.end(), ',', ' ');
        std::istringstream words(line);
        std::string list;
        for (std::string word; words >> word;) list += (list.empty() ? "" : ",") + word;
        if (list.empty()) continue;
        Result<VolumePolicy> read = parse_weights_into(list, base, named);
        if (!read) return Error{read.error().message, path.string(), line_number};
        base = read.value();
        any = true;
    }
    if (!any)
        return Error{"no type=weight entries (the file hbvh calibrate -o writes has one line of them)", path.string()};
    return base;
}

Result<VolumePolicy> type_weights_from(std::string_view list_or_file, VolumePolicy base) {
    if (!list_or_file.starts_with('@')) return parse_type_weights(list_or_file, base);
    if (list_or_file.size() == 1) return Error{"type weights: '@' needs a file name after it"};
    return read_type_weights_file(std::filesystem::path(list_or_file.substr(1)), base);
}

}  // namespace hbvh
