# SPDX-License-Identifier: MIT
# The builder flags in the commands that build only when given a primitive set (collide, simulate, export, view),
# as a user's review found them (2026-12-07): a bad flag is a usage error (exit 2) as in build and stats; simulate
# names the builder that made its tree (a --quality preset, or "stored") and the query; a --type-weight @FILE that is
# a pipe is read once (stats read it twice and crashed on the empty second read); calibrate -o - writes only the
# weights to standard output, so that they pipe into --type-weight.
#   cmake -DCLI=<hbvh> -DSOURCE=<repo> -DOUT=<dir> -P builder_flags.cmake
set(chair ${SOURCE}/data/models/chair.xml)
function(expect_exit code)
  execute_process(COMMAND ${CLI} ${ARGN} RESULT_VARIABLE got OUTPUT_QUIET ERROR_VARIABLE err)
  if(NOT got EQUAL code)
    message(FATAL_ERROR "`hbvh ${ARGN}` exited ${got}, expected ${code}:\n${err}")
  endif()
endfunction()
expect_exit(2 collide ${chair} ${chair} -a no-such-builder)
expect_exit(2 simulate ${chair} --types foo --collisions 10)
expect_exit(2 export ${chair} --type-weight obb=-1 -o ${OUT}/flags.gltf)
expect_exit(2 view ${chair} -a no-such-builder -o ${OUT}/flags.html)

execute_process(COMMAND ${CLI} simulate ${chair} --quality fast --collisions 20 --json RESULT_VARIABLE code
                OUTPUT_VARIABLE out ERROR_VARIABLE err)
string(JSON algorithm GET "${out}" algorithm)
string(JSON query GET "${out}" query)
if(NOT code EQUAL 0 OR NOT algorithm STREQUAL "fast" OR NOT query STREQUAL "tandem")
  message(FATAL_ERROR "simulate --quality fast: exit ${code}, algorithm '${algorithm}', query '${query}'\n${err}")
endif()
execute_process(COMMAND ${CLI} build ${chair} -a split -o ${OUT}/flags_stored.xml RESULT_VARIABLE code)
execute_process(COMMAND ${CLI} simulate ${OUT}/flags_stored.xml --collisions 20 --two-level-query --json
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
string(JSON algorithm GET "${out}" algorithm)
string(JSON query GET "${out}" query)
if(NOT code EQUAL 0 OR NOT algorithm STREQUAL "stored" OR NOT query STREQUAL "two-level")
  message(FATAL_ERROR "simulate on a stored tree: exit ${code}, algorithm '${algorithm}', query '${query}'\n${err}")
endif()
# Flags that steer a build, given with a stored hierarchy: used as it is, with a warning.
execute_process(COMMAND ${CLI} stats ${OUT}/flags_stored.xml -a two-level RESULT_VARIABLE code OUTPUT_QUIET
                ERROR_VARIABLE err)
if(NOT code EQUAL 0 OR NOT err MATCHES "stores a hierarchy, which is measured as it is")
  message(FATAL_ERROR "stats on a stored tree with -a: exit ${code}, stderr:\n${err}")
endif()

execute_process(COMMAND ${CLI} calibrate --primitives 40 --queries 20 --passes 1 -o -
                COMMAND ${CLI} stats ${chair} -a split --type-weight @/dev/stdin
                RESULTS_VARIABLE codes OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT codes STREQUAL "0;0" OR NOT out MATCHES "cost")
  message(FATAL_ERROR "calibrate -o - | stats --type-weight @/dev/stdin: exits ${codes}\n${out}\n${err}")
endif()
