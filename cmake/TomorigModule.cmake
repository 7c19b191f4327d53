# tomorig_add_module(NAME SOURCES... [PUBLIC_DEPS ...] [PRIVATE_DEPS ...])
# One library per top-level folder: public headers in <folder>/include/tomorig/<folder>/,
# implementation in <folder>/src/.
function(tomorig_add_module name)
  cmake_parse_arguments(ARG "" "" "SOURCES;PUBLIC_DEPS;PRIVATE_DEPS" ${ARGN})
  if(NOT ARG_SOURCES)  # a folder whose code has not arrived yet still links
    set(empty ${CMAKE_CURRENT_BINARY_DIR}/${name}_empty.cpp)
    file(WRITE ${empty} "// no sources yet\n")
    set(ARG_SOURCES ${empty})
  endif()
  add_library(tomorig_${name} STATIC ${ARG_SOURCES})
  add_library(tomorig::${name} ALIAS tomorig_${name})
  target_include_directories(tomorig_${name} PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/include
                                             PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src)
  target_link_libraries(tomorig_${name} PUBLIC ${ARG_PUBLIC_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
  set_target_properties(tomorig_${name} PROPERTIES POSITION_INDEPENDENT_CODE ON)
endfunction()

# tomorig_add_test(MODULE SOURCES... [DEPS ...]) -> one GoogleTest executable per module,
# registered with ctest through gtest_discover_tests.
#
# Real-data tests (names matching TOMORIG_REAL_DATA_TESTS: they read ../shared/data) carry the
# ctest label `real_data` (`ctest -L real_data`). Where ../shared/data exists (CI, the main
# checkout) TOMORIG_REAL_DATA_REQUIRED is 1 and they fail, not skip, when their sample is missing
# (tests/support/real_data.h). A suite whose sources run the tomorig binary (they include
# cli_runner.h or child_process.h) depends on it, so it is built first.
set(TOMORIG_REAL_DATA_TESTS "*RealData*:*Fluidimage*" CACHE STRING "gtest filter of the tests that read ../shared/data")
# Tests that judge real-time behaviour against a device's own clock (the Aravis GigE fake polls
# its software triggers on a 40 ms grid): they run alone (ctest RUN_SERIAL), since a parallel
# test stealing one of the two cores moves frames across that grid.
set(TOMORIG_SERIAL_TESTS "GigEFake*" CACHE STRING "gtest filter of the tests ctest runs alone")
if(EXISTS "${PROJECT_SOURCE_DIR}/../shared/data")
  set(TOMORIG_REAL_DATA_DEFAULT ON)
else()
  set(TOMORIG_REAL_DATA_DEFAULT OFF)
endif()
option(TOMORIG_REQUIRE_REAL_DATA "Real-data tests fail instead of skipping when their sample is missing"
       ${TOMORIG_REAL_DATA_DEFAULT})

# TOMORIG_TEST_CLI=OFF: the suites no longer wait for the tomorig binary, so a build of a few
# suites' targets compiles only their libraries; their CLI tests then skip (tomorig_built()).
# The CI sanitizer tree uses it (scripts/test-sanitized.sh): the whole instrumented binary does
# not fit CI's time limit.
option(TOMORIG_TEST_CLI "Suites that run the tomorig binary depend on it (OFF: their CLI tests skip)" ON)

function(tomorig_add_test module)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_executable(test_${module} ${ARG_SOURCES})
  target_link_libraries(test_${module} PRIVATE ${ARG_DEPS} tomorig::large_pages GTest::gtest GTest::gtest_main)
  if(TOMORIG_REQUIRE_REAL_DATA)
    set(real_data_required 1)
  else()
    set(real_data_required 0)
  endif()
  target_compile_definitions(test_${module} PRIVATE
      TOMORIG_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
      TOMORIG_SHARED_DIR="${PROJECT_SOURCE_DIR}/../shared"
      TOMORIG_BINARY="$<TARGET_FILE:tomorig>"
      TOMORIG_REAL_DATA_REQUIRED=${real_data_required})
  foreach(source ${ARG_SOURCES})
    get_filename_component(path ${source} ABSOLUTE)
    file(STRINGS ${path} runs_binary REGEX "#include \"(cli_runner|child_process)\\.h\"")
    if(runs_binary AND TARGET tomorig AND TOMORIG_TEST_CLI)
      add_dependencies(test_${module} tomorig)
      break()
    endif()
  endforeach()
  include(GoogleTest)
  gtest_discover_tests(test_${module} DISCOVERY_TIMEOUT 60 TEST_FILTER "-${TOMORIG_REAL_DATA_TESTS}:${TOMORIG_SERIAL_TESTS}"
                       PROPERTIES TIMEOUT 300)
  gtest_discover_tests(test_${module} DISCOVERY_TIMEOUT 60 TEST_FILTER "${TOMORIG_SERIAL_TESTS}"
                       PROPERTIES TIMEOUT 300 RUN_SERIAL TRUE LABELS serial)
  gtest_discover_tests(test_${module} DISCOVERY_TIMEOUT 60 TEST_FILTER "${TOMORIG_REAL_DATA_TESTS}"
                       PROPERTIES TIMEOUT 300 LABELS real_data)
endfunction()
