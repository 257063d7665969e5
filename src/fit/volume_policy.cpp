// SPDX-License-Identifier: MIT
#include "hbvh/fit/volume_policy.hpp"

#include <charconv>
#include <cmath>
#include <string>

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

Result<VolumePolicy> parse_type_weights(std::string_view list, VolumePolicy base) {
    for (std::string_view entry : split_list(list)) {
        const std::size_t equals = entry.find('=');
        if (equals == std::string_view::npos)
            return Error{"type weight '" + std::string(entry) + "' is not of the form type=weight"};
        const std::optional<BvType> type = parse_bv_type(entry.substr(0, equals));
        if (!type) return Error{"unknown bounding-volume type in weight '" + std::string(entry) + "'"};
        const std::string_view number = entry.substr(equals + 1);
        double weight = 0.0;
        const auto [end, code] = std::from_chars(number.data(), number.data() + number.size(), weight);
        if (code != std::errc{} || end != number.data() + number.size() || !std::isfinite(weight) || weight <= 0.0)
            return Error{"type weight '" + std::string(entry) + "' needs a positive finite number"};
        base.weight[static_cast<std::size_t>(*type)] = weight;
    }
    return base;
}

}  // namespace hbvh
