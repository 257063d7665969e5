# SPDX-License-Identifier: MIT
# Runs one CLI command and checks its exit code and stderr, because ctest alone cannot check both
# (PASS_REGULAR_EXPRESSION ignores the exit code). Called as:
#   cmake -DCLI=<hbvh> -DARGS=<arguments separated by |> -DEXPECT_EXIT=<n> [-DEXPECT_STDERR=<regex>] [-DSTDIN=<file>]
#         [-DSTDOUT=<file>] -P expect.cmake
string(REPLACE "|" ";" ARGS "${ARGS}")
if(DEFINED STDIN)
  set(input INPUT_FILE ${STDIN})
endif()
set(output OUTPUT_QUIET)
if(DEFINED STDOUT)
  set(output OUTPUT_FILE ${STDOUT})
endif()
execute_process(COMMAND ${CLI} ${ARGS} ${input} RESULT_VARIABLE code ${output} ERROR_VARIABLE err TIMEOUT 60)
if(NOT code STREQUAL EXPECT_EXIT)
  message(FATAL_ERROR "expected exit ${EXPECT_EXIT}, got ${code}; stderr:\n${err}")
endif()
if(DEFINED EXPECT_STDERR AND NOT err MATCHES "${EXPECT_STDERR}")
  message(FATAL_ERROR "stderr does not match '${EXPECT_STDERR}':\n${err}")
endif()
