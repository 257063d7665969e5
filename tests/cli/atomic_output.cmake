# SPDX-License-Identifier: MIT
# Every command that writes a file (build, convert, export to .gltf/.dot/.svg, view, generate) must never leave
# a partial output: a failure leaves an existing output byte-identical and no temporary file behind, after bad
# input, with the output path being a directory, and (unless running as root) in a read-only directory.
# Last, a `generate` killed part-way (execute_process TIMEOUT kills it) leaves the old file or a complete new one.
#   cmake -DCLI=<hbvh> -DSOURCE=<repo> -DWORK=<scratch dir> -P atomic_output.cmake
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
set(good ${SOURCE}/data/models/chair.xml)
set(bad ${SOURCE}/tests/cli/inputs/malformed.xml)

function(run expect_exit)
  execute_process(COMMAND ${CLI} ${ARGN} RESULT_VARIABLE code OUTPUT_QUIET ERROR_VARIABLE err TIMEOUT 120)
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

function(expect_unchanged path hash what)
  file(SHA256 ${path} now)
  if(NOT now STREQUAL hash)
    message(FATAL_ERROR "${what} changed the existing output ${path}")
  endif()
endfunction()

# check_command(<name> <output extension> <input placeholder args...>): the arguments use INPUT for the input
# file and OUTPUT for the output path; generate has no input, so its bad-input step is skipped.
function(check_command name extension)
  set(dir ${WORK}/${name})
  file(MAKE_DIRECTORY ${dir})
  set(out ${dir}/out.${extension})
  string(REPLACE "INPUT" "${good}" good_args "${ARGN}")
  string(REPLACE "OUTPUT" "${out}" good_args "${good_args}")
  run(0 ${good_args})
  file(SHA256 ${out} before)

  # Bad input: fails before writing; the old output stays.
  if("${ARGN}" MATCHES "INPUT")
    string(REPLACE "INPUT" "${bad}" bad_args "${ARGN}")
    string(REPLACE "OUTPUT" "${out}" bad_args "${bad_args}")
    run(1 ${bad_args})
    expect_unchanged(${out} ${before} "`${name}` on bad input")
  endif()
  expect_no_temporaries(${dir})

  # The output path is a directory: refused before anything is written.
  file(MAKE_DIRECTORY ${dir}/taken.${extension})
  string(REPLACE "INPUT" "${good}" taken_args "${ARGN}")
  string(REPLACE "OUTPUT" "${dir}/taken.${extension}" taken_args "${taken_args}")
  run(1 ${taken_args})
  if(NOT IS_DIRECTORY ${dir}/taken.${extension})
    message(FATAL_ERROR "`${name}` replaced the directory at its output path")
  endif()
  expect_no_temporaries(${dir})

  # Read-only directory holding a previous output. Root ignores permissions, so probe first.
  set(locked ${dir}/locked)
  file(MAKE_DIRECTORY ${locked})
  file(COPY_FILE ${out} ${locked}/out.${extension})
  file(CHMOD ${locked} PERMISSIONS OWNER_READ OWNER_EXECUTE)
  execute_process(COMMAND ${CMAKE_COMMAND} -E touch ${locked}/probe RESULT_VARIABLE writable)
  if(writable STREQUAL "0")
    file(REMOVE ${locked}/probe)
  else()
    string(REPLACE "INPUT" "${good}" locked_args "${ARGN}")
    string(REPLACE "OUTPUT" "${locked}/out.${extension}" locked_args "${locked_args}")
    run(1 ${locked_args})
    expect_unchanged(${locked}/out.${extension} ${before} "`${name}` into a read-only directory")
    expect_no_temporaries(${locked})
  endif()
  file(CHMOD ${locked} PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE)
endfunction()

check_command(build xml build INPUT -o OUTPUT)
check_command(convert xml convert INPUT -o OUTPUT)
check_command(export_gltf gltf export INPUT -a two-level -o OUTPUT)
check_command(export_dot dot export INPUT -a two-level -o OUTPUT)
check_command(view html view INPUT -a two-level -o OUTPUT)
check_command(generate xml generate --count 50 -o OUTPUT)
find_program(DOT_PROGRAM dot)
if(DOT_PROGRAM)
  check_command(export_svg svg export INPUT -a two-level -o OUTPUT)
else()
  message(STATUS "Graphviz dot not found: export to .svg not checked")
endif()

# Interrupted: a large `generate` killed after a second (SIGKILL from execute_process's TIMEOUT) must leave the
# previous file or the complete new one, never a prefix. A killed process cannot remove its temporary file, so
# that is allowed here; it is hidden (leading dot) and named after the output.
set(out ${WORK}/killed.xml)
run(0 generate --count 3 -o ${out})
file(SHA256 ${out} before)
execute_process(COMMAND ${CLI} generate --count 1000000 --seed 2 -o ${out} TIMEOUT 1 RESULT_VARIABLE code
                OUTPUT_QUIET ERROR_QUIET)
file(SHA256 ${out} after)
if(NOT after STREQUAL before)
  file(SIZE ${out} size)
  math(EXPR tail_offset "${size} - 64")
  file(READ ${out} tail OFFSET ${tail_offset})
  if(NOT code STREQUAL "0" OR NOT tail MATCHES "</hierarchy>[ \r\n]*$")
    message(FATAL_ERROR "an interrupted generate (exit '${code}') left a changed, incomplete ${out}")
  endif()
endif()
file(REMOVE_RECURSE ${WORK})
