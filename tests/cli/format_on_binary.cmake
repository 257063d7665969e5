# SPDX-License-Identifier: MIT
# `--format urdf|mjcf|mesh` on a .hbvh file: exit 1 and a message that says it is a binary hierarchy (until
# 2026-12-07 the URDF reader called it malformed XML at a line of the binary file).
#   cmake -DCLI=<hbvh> -DSOURCE=<repo> -DOUT=<dir> -P format_on_binary.cmake
set(tree ${OUT}/format_on_binary.hbvh)
execute_process(COMMAND ${CLI} build ${SOURCE}/data/models/chair.xml -a split -o ${tree} RESULT_VARIABLE code)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "building ${tree} exited ${code}")
endif()
foreach(format urdf mjcf mesh)
  execute_process(COMMAND ${CLI} stats ${tree} --format ${format} RESULT_VARIABLE code ERROR_VARIABLE err OUTPUT_QUIET)
  if(NOT code EQUAL 1 OR NOT err MATCHES "is an .hbvh hierarchy \\(its first bytes say so\\), not ${format}")
    message(FATAL_ERROR "--format ${format} on a .hbvh file: exit ${code}, stderr:\n${err}")
  endif()
endforeach()
