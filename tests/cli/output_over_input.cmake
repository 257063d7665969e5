# SPDX-License-Identifier: MIT
# A command whose output is its own input file must not replace it when that loses the input: build and convert
# over an imported model (MJCF, URDF, a mesh: survey XML keeps only its primitives), export over any input (glTF,
# DOT and SVG are no input of hbvh's). Usage error (exit 2), the input untouched, whichever path names the file
# (the same name, another spelling, a symbolic link). Over its own formats (survey XML, .hbvh) build may rewrite
# the file in place, since nothing it holds is lost.
#   cmake -DCLI=<hbvh> -DSOURCE=<repo> -DWORK=<scratch dir> -P output_over_input.cmake
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
file(WRITE ${WORK}/robot.xml
     "<mujoco model=\"robot\">\n  <worldbody>\n    <geom type=\"sphere\" size=\"0.1\"/>\n"
     "    <geom type=\"box\" pos=\"0.5 0 0\" size=\"0.1 0.2 0.3\"/>\n  </worldbody>\n</mujoco>\n")
file(CREATE_LINK ${WORK}/robot.xml ${WORK}/link.xml SYMBOLIC)
file(COPY ${SOURCE}/data/models/chair.xml DESTINATION ${WORK})
file(SHA256 ${WORK}/robot.xml robot_hash)
file(SHA256 ${WORK}/chair.xml chair_hash)

function(run expect_exit expect_stderr)
  execute_process(COMMAND ${CLI} ${ARGN} WORKING_DIRECTORY ${WORK} RESULT_VARIABLE code OUTPUT_QUIET
                  ERROR_VARIABLE err TIMEOUT 120)
  if(NOT code STREQUAL expect_exit)
    message(FATAL_ERROR "`hbvh ${ARGN}`: expected exit ${expect_exit}, got ${code}:\n${err}")
  endif()
  if(NOT err MATCHES "${expect_stderr}")
    message(FATAL_ERROR "`hbvh ${ARGN}`: stderr does not match '${expect_stderr}':\n${err}")
  endif()
endfunction()

function(expect_hash path hash what)
  file(SHA256 ${path} now)
  if(NOT now STREQUAL hash)
    message(FATAL_ERROR "${what} replaced ${path}")
  endif()
endfunction()

set(refusal "the output '.*' is the input file \\(an imported model")
run(2 "hbvh convert: ${refusal}" convert robot.xml -o robot.xml)
expect_hash(${WORK}/robot.xml ${robot_hash} "convert over its MJCF input")
run(2 "hbvh build: ${refusal}" build robot.xml -o ./robot.xml)
expect_hash(${WORK}/robot.xml ${robot_hash} "build over its MJCF input, spelled ./robot.xml")
run(2 "hbvh build: ${refusal}" build robot.xml -o link.xml)
expect_hash(${WORK}/robot.xml ${robot_hash} "build over its MJCF input through a symbolic link")
run(2 "hbvh convert: ${refusal}" convert link.xml -o ${WORK}/robot.xml)
expect_hash(${WORK}/robot.xml ${robot_hash} "convert of a link over the file it names")
run(2 "hbvh export: the output '.*' is the input file: writing it" export chair.xml --format dot -o chair.xml)
expect_hash(${WORK}/chair.xml ${chair_hash} "export over its survey XML input")

# Another output is fine, and so is survey XML rewritten in place (a primitive set becomes its hierarchy).
run(0 "" convert robot.xml -o robot.survey.xml)
run(0 "" build chair.xml -o chair.xml)
run(0 "" stats chair.xml)
