# SPDX-License-Identifier: MIT
# export to SVG renders through a temporary directory: with TMPDIR naming no directory it must fail with a message
# and exit 1 (std::filesystem::temp_directory_path threw, and the process aborted). Called with -DCLI -DSOURCE -DOUT.
execute_process(COMMAND ${CMAKE_COMMAND} -E env TMPDIR=${OUT}/no-such-tmpdir
                        ${CLI} export ${SOURCE}/data/models/chair.xml -a fast -o ${OUT}/no_tmpdir.svg
                RESULT_VARIABLE code ERROR_VARIABLE err OUTPUT_QUIET TIMEOUT 60)
if(NOT code STREQUAL "1")
  message(FATAL_ERROR "expected exit 1, got ${code}; stderr:\n${err}")
endif()
# Without Graphviz the command stops earlier, for that reason; either way it names why.
if(NOT err MATCHES "no directory for temporary files|'dot' was not found")
  message(FATAL_ERROR "stderr names neither the missing TMPDIR nor dot:\n${err}")
endif()
