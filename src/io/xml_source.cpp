// SPDX-License-Identifier: MIT
// XmlSource and number parsing for the MJCF and URDF importers.
#include "xml_source.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <iterator>
#include <sstream>

namespace hbvh::detail {

std::optional<std::string> read_file_bytes(const std::string& path) {
    std::ifstream stream(path, std::ios::binary);
    if (!stream) return std::nullopt;
    std::ostringstream bytes;
    bytes << stream.rdbuf();
    if (stream.bad()) return std::nullopt;
    return std::move(bytes).str();
}

Result<std::unique_ptr<XmlSource>> XmlSource::load(const std::string& path) {
    std::optional<std::string> bytes = read_file_bytes(path);
    if (!bytes) return Error("cannot open file", path);
    auto source = std::make_unique<XmlSource>();
    source->path_ = path;
    source->text_ = std::move(*bytes);
    source->line_starts_.push_back(0);
    for (std::size_t i = 0; i < source->text_.size(); ++i)
        if (source->text_[i] == '\n') source->line_starts_.push_back(i + 1);
    // parse_default keeps offsets meaningful; the text is parsed from our own copy so offsets index text_.
    const pugi::xml_parse_result parsed =
        source->document_.load_buffer(source->text_.data(), source->text_.size(), pugi::parse_default);
    if (!parsed)
        return Error(std::string("malformed XML: ") + parsed.description(), path, source->line_of_offset(parsed.offset));
    return source;
}

int XmlSource::line_of_offset(std::ptrdiff_t offset) const {
    if (offset < 0) return 0;
    const auto after = std::upper_bound(line_starts_.begin(), line_starts_.end(), static_cast<std::size_t>(offset));
    return static_cast<int>(std::distance(line_starts_.begin(), after));
}

bool is_representable(const BoundingVolume& volume) {
    if (const auto* sphere = std::get_if<Sphere>(&volume))
        return sphere->center.allFinite() && std::isfinite(sphere->radius);
    if (const auto* capsule = std::get_if<Capsule>(&volume))
        return capsule->p0.allFinite() && capsule->p1.allFinite() && std::isfinite(capsule->radius) &&
               std::isfinite(capsule->length()) && capsule->center().allFinite();
    if (const auto* box = std::get_if<Obb>(&volume))
        return box->center.allFinite() && box->rotation.allFinite() && Vec3(2.0 * box->half_extents).allFinite();
    const Aabb& box = std::get<Aabb>(volume);
    return box.min.allFinite() && box.max.allFinite() && Vec3(box.max - box.min).allFinite() &&
           box.center().allFinite();
}

std::optional<std::vector<double>> parse_numbers(std::string_view text) {
    std::vector<double> values;
    std::size_t i = 0;
    auto is_space = [](char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; };
    while (i < text.size()) {
        if (is_space(text[i])) {
            ++i;
            continue;
        }
        std::size_t end = i;
        while (end < text.size() && !is_space(text[end])) ++end;
        // from_chars rejects a leading '+', which XML writers do emit; skip it by hand.
        std::size_t start = i;
        if (text[start] == '+' && end - start > 1) ++start;
        double value = 0.0;
        const auto [stop, code] = std::from_chars(text.data() + start, text.data() + end, value);
        if (code != std::errc() || stop != text.data() + end || !std::isfinite(value)) return std::nullopt;
        values.push_back(value);
        i = end;
    }
    return values;
}

}  // namespace hbvh::detail
