# SPDX-License-Identifier: MIT
# End-to-end tests of `hbvh collide` on a primitive set and on a stored hierarchy: the --json pairs against pairs
# worked out by hand (tests/cli/inputs/collide_pairs.xml), --first, a separating pose, relative poses, and exit 1
# on bad input files. (Bad --pose-a/--pose-b values, exit 2, are single commands: cli_tests.cmake.)
#   cmake -DCLI=<hbvh> -DSOURCE=<source dir> -DWORK=<scratch dir> -P collide.cmake
cmake_minimum_required(VERSION 3.25)
set(inputs ${SOURCE}/tests/cli/inputs)
set(chair ${SOURCE}/data/models/chair.xml)
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})

# run(<expected exit> <stdout variable> <arguments...>): runs the CLI and fails unless it exits as expected.
function(run expected out)
  execute_process(COMMAND ${CLI} ${ARGN} RESULT_VARIABLE code OUTPUT_VARIABLE stdout ERROR_VARIABLE stderr TIMEOUT 120)
  if(NOT code STREQUAL expected)
    string(JOIN " " command ${ARGN})
    message(FATAL_ERROR "hbvh ${command}: expected exit ${expected}, got ${code}\nstdout:\n${stdout}\nstderr:\n${stderr}")
  endif()
  set(${out} "${stdout}" PARENT_SCOPE)
  set(${out}_stderr "${stderr}" PARENT_SCOPE)
endfunction()

# collide_json(<prefix> <arguments...>): `hbvh collide <arguments> --json`, exit 0; sets <prefix>_intersecting
# (ON/OFF) and <prefix>_pairs, the pairs as a list of "i j" in output order.
function(collide_json prefix)
  run(0 json collide ${ARGN} --json)
  string(JSON intersecting GET "${json}" intersecting)
  string(JSON count LENGTH "${json}" pairs)
  set(pairs "")
  if(count GREATER 0)
    math(EXPR last "${count} - 1")
    foreach(k RANGE ${last})
      string(JSON i GET "${json}" pairs ${k} 0)
      string(JSON j GET "${json}" pairs ${k} 1)
      list(APPEND pairs "${i} ${j}")
    endforeach()
  endif()
  set(${prefix}_intersecting ${intersecting} PARENT_SCOPE)
  set(${prefix}_pairs "${pairs}" PARENT_SCOPE)
endfunction()

function(expect_equal what actual expected)
  if(NOT "${actual}" STREQUAL "${expected}")
    message(FATAL_ERROR "${what}: got '${actual}', expected '${expected}'")
  endif()
endfunction()

# Stage 1: the hand-worked primitive set, b shifted by 3.5 along x. By hand (each shape against each shifted one):
#   1 cube [4,6]^x vs 0' ball at 3.5, radius 1: 0.5 from the face          -> overlap
#   2 bar x in [-3,3] at y 5 vs 2' bar x in [0.5,6.5]: axes 0 apart          -> overlap
#   3 far ball at 10 vs 1' cube [7.5,9.5]^x: 0.5 from the face                -> overlap
#   5 small ball at (4.2,-5) vs 4' diamond around (5.5,-5): centre inside     -> overlap
#   4 diamond tip at x 3.414 vs 4' diamond tip at 4.086: 0.67 apart, and every other pair further -> separate
set(expected_pairs "1 0;2 2;3 1;5 4")
set(pairs_file ${inputs}/collide_pairs.xml)
collide_json(shifted ${pairs_file} ${pairs_file} --pose-b "3.5 0 0")
expect_equal("collide_pairs.xml shifted by 3.5: intersecting" "${shifted_intersecting}" ON)
expect_equal("collide_pairs.xml shifted by 3.5: pairs" "${shifted_pairs}" "${expected_pairs}")

# Only the relative pose matters: the same shift as 7 numbers with an unnormalised identity quaternion, both
# objects moved together, and both turned by 180 degrees about z (b's translation is R * (3.5, 0, 0) + a's).
foreach(poses "--pose-b;3.5 0 0 2 0 0 0"
              "--pose-a;0 0 7;--pose-b;3.5 0 7"
              "--pose-a;1 2 3 0 0 0 1;--pose-b;-2.5 2 3 0 0 0 1")
  collide_json(moved ${pairs_file} ${pairs_file} ${poses})
  expect_equal("collide_pairs.xml with ${poses}: pairs" "${moved_pairs}" "${expected_pairs}")
endforeach()
# Swapping the objects swaps each pair (b shifted by -3.5 relative to a); --algorithm changes the tree, not pairs.
collide_json(swapped ${pairs_file} ${pairs_file} --pose-a "3.5 0 0")
expect_equal("collide_pairs.xml, a shifted: pairs" "${swapped_pairs}" "0 1;1 3;2 2;4 5")
foreach(algorithm two-level split insertion)
  collide_json(built ${pairs_file} ${pairs_file} --pose-b "3.5 0 0" -a ${algorithm})
  expect_equal("collide_pairs.xml -a ${algorithm}: pairs" "${built_pairs}" "${expected_pairs}")
endforeach()

# --first: exactly one pair, one of the full set.
collide_json(first ${pairs_file} ${pairs_file} --pose-b "3.5 0 0" --first)
expect_equal("--first: intersecting" "${first_intersecting}" ON)
list(LENGTH first_pairs first_count)
expect_equal("--first: number of pairs" "${first_count}" 1)
list(FIND expected_pairs "${first_pairs}" found)
if(found LESS 0)
  message(FATAL_ERROR "--first reported '${first_pairs}', which is not one of '${expected_pairs}'")
endif()

# A separating pose: b 50 above a, far from every primitive (the set spans at most 2 in z).
foreach(mode "" --first)
  collide_json(apart ${pairs_file} ${pairs_file} --pose-b "0 0 50" ${mode})
  expect_equal("separated ${mode}: intersecting" "${apart_intersecting}" OFF)
  expect_equal("separated ${mode}: pairs" "${apart_pairs}" "")
endforeach()
# The text output says the same.
run(0 text collide ${pairs_file} ${pairs_file} --pose-b "0 0 50")
if(NOT text MATCHES "^separate\n")
  message(FATAL_ERROR "text output for a separating pose does not start with 'separate':\n${text}")
endif()
run(0 text collide ${pairs_file} ${pairs_file} --pose-b "3.5 0 0")
if(NOT text MATCHES "^intersecting\n  1 0\n  2 2\n  3 1\n  5 4\n")
  message(FATAL_ERROR "text output for the shifted set does not list the four pairs:\n${text}")
endif()

# Stage 2: a stored hierarchy (written by hbvh build) against itself and against its primitive set. At the
# identity every primitive overlaps its own copy; under any pose the number of overlapping pairs cannot depend
# on whether the primitives come as a set or as a hierarchy (the hierarchy file may list them in another order,
# so pairs are compared by count, and (i i) by index within one file). Every tree here is split's: which builder
# made the trees cannot change the pairs, and auto's (at 13 primitives the cheapest of six builders, each refined;
# with bnb-exact among them it took 2.5-3 s per tree under the sanitizers) would only lengthen it.
run(0 ignored build ${chair} -a split -o ${WORK}/chair.hbvh.xml)
collide_json(tree ${WORK}/chair.hbvh.xml ${WORK}/chair.hbvh.xml)
expect_equal("chair hierarchy vs itself: intersecting" "${tree_intersecting}" ON)
foreach(i RANGE 12)
  list(FIND tree_pairs "${i} ${i}" found)
  if(found LESS 0)
    message(FATAL_ERROR "chair hierarchy vs itself at the identity lacks the pair '${i} ${i}': ${tree_pairs}")
  endif()
endforeach()
collide_json(set ${chair} ${chair} -a split)
list(LENGTH tree_pairs tree_count)
list(LENGTH set_pairs set_count)
expect_equal("chair at the identity: pairs of the hierarchy vs pairs of the set" "${tree_count}" "${set_count}")
set(turned "0.3 0 0 0.92 0 0.38 0")
collide_json(tree_turned ${WORK}/chair.hbvh.xml ${WORK}/chair.hbvh.xml --pose-b "${turned}")
collide_json(set_turned ${chair} ${chair} --pose-b "${turned}" -a split)
collide_json(mixed_turned ${WORK}/chair.hbvh.xml ${chair} --pose-b "${turned}" -a split)
list(LENGTH tree_turned_pairs tree_turned_count)
list(LENGTH set_turned_pairs set_turned_count)
list(LENGTH mixed_turned_pairs mixed_turned_count)
expect_equal("chair turned: hierarchy pairs vs set pairs" "${tree_turned_count}" "${set_turned_count}")
expect_equal("chair turned: hierarchy-vs-set pairs vs set pairs" "${mixed_turned_count}" "${set_turned_count}")
if(set_turned_count EQUAL 0)
  message(FATAL_ERROR "chair vs chair turned by ${turned}: expected overlapping pairs, got none")
endif()
collide_json(tree_apart ${WORK}/chair.hbvh.xml ${WORK}/chair.hbvh.xml --pose-b "0 0 5")
expect_equal("chair hierarchy 5 apart: intersecting" "${tree_apart_intersecting}" OFF)
expect_equal("chair hierarchy 5 apart: pairs" "${tree_apart_pairs}" "")

# Many pairs: 300 coincident spheres meet pairwise, 90 000 pairs whose JSON (1.3 MB) is written in pieces of 1 MB
# (before 2026-12-07 it was built as a DOM first: 2.9 GB for 3 000 spheres, and std::terminate when memory ran out).
set(coincident "<hierarchy>\n")
foreach(k RANGE 1 300)
  string(APPEND coincident "  <volume type=\"sphere\" pos=\"0 0 0\" radius=\"1\"/>\n")
endforeach()
file(WRITE ${WORK}/coincident.xml "${coincident}</hierarchy>\n")
run(0 many collide ${WORK}/coincident.xml ${WORK}/coincident.xml --json)
string(JSON many_count LENGTH "${many}" pairs)
string(JSON many_last GET "${many}" pairs 89999)
string(JSON many_tests GET "${many}" primitive_tests)
expect_equal("300 coincident spheres: pair count" "${many_count}" 90000)
expect_equal("300 coincident spheres: last pair" "${many_last}" "[ 299, 299 ]")
expect_equal("300 coincident spheres: primitive tests" "${many_tests}" 90000)

# Stage 3: bad input files are exit 1 with a message naming the file.
run(1 ignored collide ${inputs}/does-not-exist.xml ${pairs_file})
if(NOT ignored_stderr MATCHES "does-not-exist.xml")
  message(FATAL_ERROR "missing input: the message does not name the file:\n${ignored_stderr}")
endif()
run(1 ignored collide ${pairs_file} ${inputs}/malformed.xml)
if(NOT ignored_stderr MATCHES "malformed.xml:1: malformed XML")
  message(FATAL_ERROR "malformed input: the message does not name the file and line:\n${ignored_stderr}")
endif()
file(REMOVE_RECURSE ${WORK})

# --names: the same model read from its source and from a hierarchy built from it numbers its primitives differently
# (survey XML lists them in tree order), so the pairs' indices differ; their names must not (2026-12-08).
file(MAKE_DIRECTORY ${WORK})
run(0 built build ${chair} -a split -o ${WORK}/chair_built.xml)
set(pose "0.3 0.05 0 0.96 0 0.28 0")
run(0 from_source collide ${chair} ${chair} --pose-b "${pose}" --json --names)
run(0 from_built collide ${chair} ${WORK}/chair_built.xml --pose-b "${pose}" --json --names)
foreach(which from_source from_built)
  string(JSON count LENGTH "${${which}}" names)
  string(JSON pair_count LENGTH "${${which}}" pairs)
  if(count EQUAL 0 OR NOT count EQUAL pair_count)
    message(FATAL_ERROR "${which}: ${count} names for ${pair_count} pairs:\n${${which}}")
  endif()
  set(${which}_names "")
  math(EXPR last "${count} - 1")
  foreach(k RANGE ${last})
    string(JSON a GET "${${which}}" names ${k} 0)
    string(JSON b GET "${${which}}" names ${k} 1)
    list(APPEND ${which}_names "${a}/${b}")
  endforeach()
  list(SORT ${which}_names)
endforeach()
if(NOT from_source_names STREQUAL from_built_names)
  message(FATAL_ERROR "the same contacts by name differ:\nsource: ${from_source_names}\nbuilt: ${from_built_names}")
endif()
run(0 text collide ${chair} ${chair} --pose-b "${pose}" --names)
if(NOT text MATCHES "\n  [0-9]+ [0-9]+ \"[a-z_]+\" \"[a-z_]+\"\n")
  message(FATAL_ERROR "collide --names, text:\n${text}")
endif()
