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
function(tomorig_add_test module)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_executable(test_${module} ${ARG_SOURCES})
  target_link_libraries(test_${module} PRIVATE ${ARG_DEPS} tomorig::large_pages GTest::gtest GTest::gtest_main)
  target_compile_definitions(test_${module} PRIVATE
      TOMORIG_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
      TOMORIG_SHARED_DIR="${PROJECT_SOURCE_DIR}/../shared"
      TOMORIG_BINARY="$<TARGET_FILE:tomorig>")
  include(GoogleTest)
  gtest_discover_tests(test_${module} DISCOVERY_TIMEOUT 60 PROPERTIES TIMEOUT 300)
endfunction()
