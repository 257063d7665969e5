# SPDX-License-Identifier: MIT
# `hbvh build` on COUNT coincident unit spheres, generated here because such a file is too big to commit: every
# split and merge ties (the worst case for the builders). Must exit 0 within the test's timeout,
# with every sphere in the output.
#   cmake -DCLI=<hbvh> -DWORK=<scratch dir> -DCOUNT=<n> -P coincident.cmake
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
string(REPEAT "<volume type=\"sphere\" pos=\"0 0 0\" radius=\"1\"/>\n" ${COUNT} volumes)
file(WRITE ${WORK}/coincident.xml "<hierarchy>\n${volumes}</hierarchy>\n")
execute_process(COMMAND ${CLI} build ${WORK}/coincident.xml -o ${WORK}/out.xml RESULT_VARIABLE code
                OUTPUT_QUIET ERROR_VARIABLE err)
if(NOT code STREQUAL "0")
  message(FATAL_ERROR "build of ${COUNT} coincident spheres: exit ${code}\n${err}")
endif()
file(STRINGS ${WORK}/out.xml spheres REGEX "type=\"sphere\"")
list(LENGTH spheres written)
if(written LESS COUNT)
  message(FATAL_ERROR "the output holds ${written} spheres, expected at least ${COUNT}")
endif()
file(REMOVE_RECURSE ${WORK})
