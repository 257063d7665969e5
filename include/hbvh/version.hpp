// SPDX-License-Identifier: MIT
// hbvh's version. The root CMakeLists.txt refuses to configure when these differ from its project(VERSION).
#pragma once

#define HBVH_VERSION_MAJOR 0          ///< Incompatible API changes (the CMake package accepts the same major only).
#define HBVH_VERSION_MINOR 1          ///< Compatible additions.
#define HBVH_VERSION_PATCH 0          ///< Fixes.
#define HBVH_VERSION_STRING "0.1.0"   ///< "MAJOR.MINOR.PATCH".

namespace hbvh {

/// The version as one comparable number: major x 10000 + minor x 100 + patch.
inline constexpr int version_number = HBVH_VERSION_MAJOR * 10000 + HBVH_VERSION_MINOR * 100 + HBVH_VERSION_PATCH;

}  // namespace hbvh
