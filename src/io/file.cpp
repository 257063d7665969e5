// SPDX-License-Identifier: MIT
// lower_case_extension (hbvh/io/file.hpp); reading and writing files is the core library's (src/files.cpp).
#include "hbvh/io/file.hpp"

#include <cctype>

namespace hbvh {

std::string lower_case_extension(const std::filesystem::path& path) {
    std::string extension = path.extension().string();
    for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return extension;
}

}  // namespace hbvh
