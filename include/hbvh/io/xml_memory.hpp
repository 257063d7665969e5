// SPDX-License-Identifier: MIT
// pugixml's memory on huge pages, for programs that read large XML files.
#pragma once

#include <cstddef>

namespace hbvh {

/// Routes the XML parser's memory (pugixml's DOM, for the survey XML, MJCF and URDF readers alike) to 64 MiB
/// regions advised for transparent huge pages. A 230 MB survey file builds about 400 MB of DOM in 32 KiB
/// blocks; in 4 KiB pages that is some 100 000 page faults, and on a virtual machine where a fault costs
/// ~10 µs they were two thirds of the read (docs/formats.md, "Huge pages for the parser and the writer").
///
/// pugixml's allocation functions are global to the process, so this is for a program's main(), not for a
/// library: it replaces whatever functions were set before. Blocks handed out before the call are still
/// freed with std::free (pugixml's default allocates with malloc), so it may be called at any time, and
/// calling it again changes nothing. A region is unmapped once every block in it is freed; a block freed
/// while others in its region live is not reused (the readers free a whole document at once).
void use_huge_pages_for_xml();

namespace detail {
/// Regions currently mapped for the XML parser, and the blocks live in them: for the tests.
struct XmlMemoryUse {
    std::size_t regions = 0;
    std::size_t live_blocks = 0;
};
[[nodiscard]] XmlMemoryUse xml_memory_use();
}  // namespace detail

}  // namespace hbvh
