// SPDX-License-Identifier: MIT
// The property every importer harness checks on what it accepts: the primitives are valid survey-format volumes,
// so hbvh's own writer and reader take them round trip (a `hbvh convert` of the file would succeed).
#pragma once

#include <cstdlib>
#include <string>

#include "hbvh/io/import.hpp"
#include "hbvh/io/xml.hpp"

namespace hbvh::fuzz {

/// Aborts (a finding for libFuzzer) unless every imported primitive survives write_primitives_xml + read_xml_string.
inline void check_imported(const Result<ImportResult>& imported) {
    if (!imported || imported->primitives.empty()) return;
    const std::string written = write_primitives_xml(imported->primitives);
    const Result<XmlModel> again = read_xml_string(written, "fuzz-roundtrip");
    if (!again || again->primitives.size() != imported->primitives.size()) std::abort();
}

}  // namespace hbvh::fuzz
