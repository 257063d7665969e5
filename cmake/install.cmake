# SPDX-License-Identifier: MIT
# Install rules (HBVH_INSTALL): the public headers, the libraries, the CMake package and the CLI.
#   cmake --install <build> --prefix <P>, then a consumer: find_package(hbvh CONFIG REQUIRED) with
#   CMAKE_PREFIX_PATH=<P> and target_link_libraries(app PRIVATE hbvh::hbvh) (or hbvh::core, hbvh::io).
# Two export sets, so that find_package(hbvh CONFIG REQUIRED COMPONENTS core) loads hbvh::core alone and never
# looks for the io dependencies (pugixml, urdfdom, assimp); without COMPONENTS every installed part is loaded.
include(CMakePackageConfigHelpers)
set(HBVH_CMAKE_INSTALL_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/hbvh)

# Headers: include/hbvh/** as it is (version.hpp is static, checked against project() by the root CMakeLists).
set(HBVH_HEADER_EXCLUDES)
if(NOT HBVH_BUILD_IO)
  set(HBVH_HEADER_EXCLUDES PATTERN io EXCLUDE)
endif()
install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/hbvh DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
        COMPONENT hbvh_development FILES_MATCHING PATTERN "*.hpp" ${HBVH_HEADER_EXCLUDES})

# hbvh::hbvh (both libraries) goes with the last part installed, so that it never names a missing target.
set(HBVH_COMPONENTS core)
if(HBVH_BUILD_IO)
  list(APPEND HBVH_COMPONENTS io)
  install(TARGETS hbvh_core EXPORT hbvhCoreTargets COMPONENT hbvh_development)
  install(TARGETS hbvh_io hbvh EXPORT hbvhIoTargets COMPONENT hbvh_development)
  install(EXPORT hbvhIoTargets NAMESPACE hbvh:: DESTINATION ${HBVH_CMAKE_INSTALL_DIR} COMPONENT hbvh_development)
else()
  install(TARGETS hbvh_core hbvh EXPORT hbvhCoreTargets COMPONENT hbvh_development)
endif()
install(EXPORT hbvhCoreTargets NAMESPACE hbvh:: DESTINATION ${HBVH_CMAKE_INSTALL_DIR} COMPONENT hbvh_development)

# Static archives need their private dependencies at the consumer's link; shared libraries do not.
get_target_property(HBVH_LIBRARY_TYPE hbvh_core TYPE)
if(HBVH_LIBRARY_TYPE STREQUAL "STATIC_LIBRARY")
  set(HBVH_STATIC_LIBRARIES TRUE)
else()
  set(HBVH_STATIC_LIBRARIES FALSE)
endif()
configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/hbvhConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/cmake/hbvhConfig.cmake
                              INSTALL_DESTINATION ${HBVH_CMAKE_INSTALL_DIR})
# 0.x.y: a consumer asking for 0.1 accepts 0.1.z and 0.2 alike; SameMajorVersion is the issue's choice.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/cmake/hbvhConfigVersion.cmake
                                 COMPATIBILITY SameMajorVersion)
install(FILES ${PROJECT_BINARY_DIR}/cmake/hbvhConfig.cmake ${PROJECT_BINARY_DIR}/cmake/hbvhConfigVersion.cmake
        DESTINATION ${HBVH_CMAKE_INSTALL_DIR} COMPONENT hbvh_development)

if(TARGET hbvh_cli)
  install(TARGETS hbvh_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT hbvh_runtime)
endif()
