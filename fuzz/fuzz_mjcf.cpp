// SPDX-License-Identifier: MIT
// libFuzzer harness for the MJCF importer: any bytes give primitives or an Error, never a crash or a hang, and
// what is accepted is valid geometry. The input is the main file; <include> resolves next to it.
#include <cstddef>
#include <cstdint>

#include "check_import.hpp"
#include "hbvh/io/mjcf.hpp"
#include "scratch_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string path = hbvh::fuzz::write_scratch_file("model.xml", data, size);
    hbvh::fuzz::check_imported(hbvh::import_mjcf(path));
    return 0;
}
