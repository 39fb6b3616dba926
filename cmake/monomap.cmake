# monomap_library(NAME <module> SRCS ... DEPS ...)
# One static library per module folder: monomap_<module>. Includes are
# rooted at src/ so code writes #include "monomap/geometry/rigid3.h".
function(monomap_library)
  cmake_parse_arguments(ARG "" "NAME" "SRCS;DEPS" ${ARGN})
  set(target monomap_${ARG_NAME})
  add_library(${target} STATIC ${ARG_SRCS})
  target_include_directories(${target} PUBLIC
    $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/src> $<INSTALL_INTERFACE:include>)
  target_link_libraries(${target} PUBLIC ${ARG_DEPS})
endfunction()

# monomap_test(NAME <name> [PIPELINE] [CATALOGUE] SRCS ... DEPS ...)
# A GoogleTest executable registered with CTest (tests discovered per case).
# Label "unit": the tests of one module (src/monomap/<module>), built
# together by the target unit_tests; "e2e": the rest (tests/, ros/, and
# module tests marked PIPELINE, which run whole pipelines). CATALOGUE:
# label "catalogue" instead, and the target catalogue_tests: the bad-input
# catalogue, which `make test-sanitize-units` runs under ASan+UBSan with the
# unit tests.
function(monomap_test)
  cmake_parse_arguments(ARG "PIPELINE;CATALOGUE" "NAME" "SRCS;DEPS" ${ARGN})
  if(NOT MONOMAP_BUILD_TESTS)
    return()
  endif()
  add_executable(${ARG_NAME} ${ARG_SRCS})
  target_link_libraries(${ARG_NAME} PRIVATE ${ARG_DEPS} GTest::gtest GTest::gtest_main)
  string(FIND "${CMAKE_CURRENT_SOURCE_DIR}/" "${PROJECT_SOURCE_DIR}/src/monomap/"
         in_module)
  # One label per test: gtest_discover_tests does not pass a list.
  set(label e2e)
  if(ARG_CATALOGUE)
    set(label catalogue)
  elseif(in_module EQUAL 0 AND NOT ARG_PIPELINE)
    set(label unit)
  endif()
  # unit_tests / catalogue_tests build the tests of that label.
  if(NOT label STREQUAL e2e)
    if(NOT TARGET ${label}_tests)
      add_custom_target(${label}_tests)
    endif()
    add_dependencies(${label}_tests ${ARG_NAME})
  endif()
  # Cases of one executable share fixture directories under /tmp, so they
  # never run concurrently (RESOURCE_LOCK); executables run in parallel.
  gtest_discover_tests(${ARG_NAME} DISCOVERY_TIMEOUT 60
                       PROPERTIES ENVIRONMENT "MONOMAP_SOURCE_DIR=${PROJECT_SOURCE_DIR}"
                                  RESOURCE_LOCK ${ARG_NAME}
                                  LABELS ${label})
endfunction()
