# SPDX-License-Identifier: MIT
# `hbvh stats --type-weight`: the cost weighs each volume by its kind's weight (it was parsed and ignored until
# 2026-12-07): with OBBs in the tree and obb=2, the weighted cost exceeds the plain one, and `build --stats` reports
# the same weighted cost.
#   cmake -DCLI=<hbvh> -DSOURCE=<repo> -DOUT=<dir> -P stats_type_weight.cmake
set(chair ${SOURCE}/data/models/chair.xml)
function(stats_cost variable)
  execute_process(COMMAND ${CLI} stats ${chair} -a split --json ${ARGN} RESULT_VARIABLE code OUTPUT_VARIABLE out
                  ERROR_VARIABLE err)
  if(NOT code EQUAL 0)
    message(FATAL_ERROR "stats ${ARGN} exited ${code}:\n${err}")
  endif()
  string(JSON cost GET "${out}" cost)
  string(JSON obbs GET "${out}" types obb)
  set(${variable} ${cost} PARENT_SCOPE)
  set(${variable}_obbs ${obbs} PARENT_SCOPE)
endfunction()
stats_cost(plain)
stats_cost(weighted --type-weight obb=2)
if(plain_obbs EQUAL 0)
  message(FATAL_ERROR "split's chair has no OBB: the test proves nothing")
endif()
if(NOT weighted GREATER plain)
  message(FATAL_ERROR "--type-weight obb=2 left the cost at ${weighted} (plain ${plain})")
endif()
execute_process(COMMAND ${CLI} build ${chair} -a split --type-weight obb=2 --stats -o ${OUT}/stats_type_weight.xml
                RESULT_VARIABLE code ERROR_VARIABLE err)
string(REGEX MATCH "cost ([0-9.e+-]+)" found "${err}")
set(build_cost ${CMAKE_MATCH_1})
# build --stats prints six significant digits: the two agree to that.
if(NOT code EQUAL 0 OR build_cost STREQUAL "")
  message(FATAL_ERROR "build --stats exited ${code}:\n${err}")
endif()
execute_process(COMMAND python3 -c "import sys; a, b = float(sys.argv[1]), float(sys.argv[2]); sys.exit(abs(a - b) > 1e-5 * abs(b))"
                        ${build_cost} ${weighted} RESULT_VARIABLE differ)
if(NOT differ EQUAL 0)
  message(FATAL_ERROR "build --stats says cost ${build_cost}, stats says ${weighted}")
endif()
