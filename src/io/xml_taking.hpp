// SPDX-License-Identifier: MIT
// The survey XML reader for text the caller hands over, for the readers inside hbvh::io.
#pragma once

#include <string>
#include <string_view>

#include "hbvh/io/xml.hpp"

namespace hbvh::detail {

/// read_xml_string, except that the reader takes `text` over and parses it in place: a large file read by
/// read_text_file (onto huge pages) is neither copied nor moved to small pages.
[[nodiscard]] Result<XmlModel> read_xml_taking(std::string text, std::string_view source_name);

}  // namespace hbvh::detail
