// SPDX-License-Identifier: MIT
// libFuzzer harness for the survey XML reader: any bytes must give a model or an Error, never a crash,
// and whatever is accepted must survive a write/read round trip.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "hbvh/io/xml.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    hbvh::Result<hbvh::XmlModel> model = hbvh::read_xml_string(text, "fuzz");
    if (!model) return 0;
    // Everything the reader accepts is valid geometry, so its own writer's output must read back
    // (written in a different order for hierarchies, hence only the count is compared).
    const std::string written = model->hierarchy ? hbvh::write_xml(*model->hierarchy)
                                                 : hbvh::write_primitives_xml(model->primitives);
    hbvh::Result<hbvh::XmlModel> again = hbvh::read_xml_string(written, "fuzz-roundtrip");
    if (!again || again->primitives.size() != model->primitives.size()) std::abort();
    return 0;
}
