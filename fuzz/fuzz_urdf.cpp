// SPDX-License-Identifier: MIT
// libFuzzer harness for the URDF importer (pugixml, then urdfdom): any bytes give primitives or an Error, never a
// crash or a hang, and what is accepted is valid geometry.
#include <cstddef>
#include <cstdint>

#include "check_import.hpp"
#include "hbvh/io/urdf.hpp"
#include "scratch_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string path = hbvh::fuzz::write_scratch_file("robot.urdf", data, size);
    hbvh::fuzz::check_imported(hbvh::import_urdf(path));
    return 0;
}
