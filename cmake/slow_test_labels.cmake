# SPDX-License-Identifier: MIT
# Read by ctest after the discovered tests (TEST_INCLUDE_FILES in tests/CMakeLists.txt): the slow GoogleTest
# tests get both labels, unit and slow.
if(hbvh_slow_tests)
  set_tests_properties(${hbvh_slow_tests} PROPERTIES LABELS "unit;slow")
endif()
