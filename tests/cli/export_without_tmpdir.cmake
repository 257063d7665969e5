# SPDX-License-Identifier: MIT
# export to SVG pipes the DOT text through Graphviz's dot and needs no scratch file: with TMPDIR naming no directory
# it still writes the SVG (until 2026-12-08 it rendered in a temporary directory, which a signal could leave behind;
# before that, std::filesystem::temp_directory_path threw here and the process aborted). Without Graphviz the command
# fails for that reason, exit 1, and says so. Called with -DCLI -DSOURCE -DOUT.
file(REMOVE ${OUT}/no_tmpdir.svg)
execute_process(COMMAND ${CMAKE_COMMAND} -E env TMPDIR=${OUT}/no-such-tmpdir
                        ${CLI} export ${SOURCE}/data/models/tie_interceptor.xml -a fast -o ${OUT}/no_tmpdir.svg
                RESULT_VARIABLE code ERROR_VARIABLE err OUTPUT_QUIET TIMEOUT 60)
if(code STREQUAL "1" AND err MATCHES "'dot' was not found")
  return()
endif()
if(NOT code STREQUAL "0")
  message(FATAL_ERROR "expected exit 0, got ${code}; stderr:\n${err}")
endif()
file(READ ${OUT}/no_tmpdir.svg svg)
# Every one of the 27 primitives' leaves is drawn, so dot read the whole DOT text.
string(REGEX MATCHALL "<g id=\"node[0-9]+\" class=\"node\">" drawn "${svg}")
list(LENGTH drawn nodes)
if(NOT svg MATCHES "</svg>[ \n]*$" OR nodes LESS 27)
  message(FATAL_ERROR "the SVG is cut short or misses nodes (${nodes} drawn)")
endif()
