# Each module folder owns its CMakeLists.txt; parents pick them up so that adding a module
# never means editing a shared list.

# facet_add_subdirectories(DIR): adds DIR itself when it has a CMakeLists.txt, otherwise every
# direct subfolder of DIR that has one, in name order.
function(facet_add_subdirectories dir)
  if(EXISTS ${dir}/CMakeLists.txt AND NOT dir STREQUAL CMAKE_CURRENT_SOURCE_DIR)
    add_subdirectory(${dir})
    return()
  endif()
  file(GLOB children LIST_DIRECTORIES true RELATIVE ${dir} ${dir}/*)
  list(SORT children)
  foreach(child IN LISTS children)
    if(IS_DIRECTORY ${dir}/${child} AND EXISTS ${dir}/${child}/CMakeLists.txt)
      add_subdirectory(${dir}/${child})
    endif()
  endforeach()
endfunction()

# facet_library(NAME SOURCES... [DEPS ...]): a static library of the project with warnings on and
# the repository root on its include path (includes read "algorithms/edges/canny.hpp").
function(facet_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(${name} STATIC ${ARG_SOURCES})
  target_include_directories(${name} PUBLIC ${PROJECT_SOURCE_DIR})
  target_link_libraries(${name} PUBLIC ${ARG_DEPS} PRIVATE facet_warnings ${ARG_PRIVATE_DEPS})
endfunction()

# facet_test(NAME SOURCES... [DEPS ...] [LABELS ...]): a GoogleTest executable registered with CTest.
# Tests run with the repository root as working directory.
function(facet_test name)
  cmake_parse_arguments(ARG "" "TIMEOUT" "SOURCES;DEPS;LABELS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} GTest::gtest GTest::gtest_main GTest::gmock facet_warnings)
  target_compile_definitions(${name} PRIVATE FACET_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
    FACET_TEST_DATA_DIR="${PROJECT_SOURCE_DIR}/tests/data")
  if(NOT ARG_TIMEOUT)
    set(ARG_TIMEOUT 300)
  endif()
  if(NOT ARG_LABELS)
    set(ARG_LABELS unit)
  endif()
  gtest_discover_tests(${name} WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}
    PROPERTIES LABELS "${ARG_LABELS}" TIMEOUT ${ARG_TIMEOUT}
    DISCOVERY_TIMEOUT 60)
endfunction()

# facet_bench(NAME SOURCES... [DEPS ...]): a benchmark executable. Every benchmark accepts
# --smoke (a few seconds, run by CTest with label "bench-smoke") and prints its table on stdout.
function(facet_bench name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS;SMOKE_ARGS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} facet_warnings)
  target_compile_definitions(${name} PRIVATE FACET_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
    FACET_TEST_DATA_DIR="${PROJECT_SOURCE_DIR}/tests/data")
  if(FACET_BUILD_TESTS)
    if(NOT ARG_SMOKE_ARGS)
      set(ARG_SMOKE_ARGS --smoke)
    endif()
    add_test(NAME ${name}.smoke COMMAND ${name} ${ARG_SMOKE_ARGS} WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
    set_tests_properties(${name}.smoke PROPERTIES LABELS bench-smoke TIMEOUT 300)
  endif()
endfunction()
