# SPDX-License-Identifier: MIT
# A failed `hbvh build` must leave an existing output untouched and no temporary file behind: after bad
# input, with the output path being a directory, and (unless running as root) in a read-only directory.
#   cmake -DCLI=<hbvh> -DSOURCE=<repo> -DWORK=<scratch dir> -P atomic_output.cmake
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
set(good ${SOURCE}/data/models/chair.xml)
set(bad ${SOURCE}/tests/cli/inputs/malformed.xml)
set(out ${WORK}/out.xml)

function(run expect_exit)
  execute_process(COMMAND ${CLI} ${ARGN} RESULT_VARIABLE code OUTPUT_QUIET ERROR_VARIABLE err TIMEOUT 60)
  if(NOT code STREQUAL expect_exit)
    message(FATAL_ERROR "`hbvh ${ARGN}`: expected exit ${expect_exit}, got ${code}:\n${err}")
  endif()
endfunction()

function(expect_no_temporaries dir)
  file(GLOB leftovers LIST_DIRECTORIES true ${dir}/.*tmp* ${dir}/*tmp*)
  if(leftovers)
    message(FATAL_ERROR "temporary files left behind: ${leftovers}")
  endif()
endfunction()

run(0 build ${good} -o ${out})
file(SHA256 ${out} before)

# Bad input: fails before writing; the old output stays.
run(1 build ${bad} -o ${out})
file(SHA256 ${out} after)
if(NOT before STREQUAL after)
  message(FATAL_ERROR "a failed build changed the existing output")
endif()
expect_no_temporaries(${WORK})

# The output path is a directory: the rename fails after the temporary was written.
file(MAKE_DIRECTORY ${WORK}/taken)
run(1 build ${good} -o ${WORK}/taken)
if(NOT IS_DIRECTORY ${WORK}/taken)
  message(FATAL_ERROR "the directory at the output path was replaced")
endif()
expect_no_temporaries(${WORK})

# Read-only directory, holding a previous output. Root ignores permissions, so probe first.
set(locked ${WORK}/locked)
file(MAKE_DIRECTORY ${locked})
file(COPY_FILE ${out} ${locked}/out.xml)
file(CHMOD ${locked} PERMISSIONS OWNER_READ OWNER_EXECUTE)
execute_process(COMMAND ${CMAKE_COMMAND} -E touch ${locked}/probe RESULT_VARIABLE writable)
if(writable STREQUAL "0")
  message(STATUS "running with write access to read-only directories (root?): read-only case skipped")
  file(REMOVE ${locked}/probe)
else()
  run(1 build ${good} -o ${locked}/out.xml)
  file(SHA256 ${locked}/out.xml locked_after)
  if(NOT before STREQUAL locked_after)
    message(FATAL_ERROR "a failed write changed the existing output")
  endif()
  expect_no_temporaries(${locked})
endif()
file(CHMOD ${locked} PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE)
file(REMOVE_RECURSE ${WORK})
