# MONOMAP_GIT_COMMIT: `git describe --always --dirty` of the source tree at
# configure time, "unknown" outside a git checkout (e.g. a release tarball).
# Written into <build>/generated/monomap/version.h for `monomap --version`.
set(MONOMAP_GIT_COMMIT "unknown")
find_package(Git QUIET)
if(GIT_FOUND)
  execute_process(
    COMMAND ${GIT_EXECUTABLE} describe --always --dirty --abbrev=12
    WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}
    OUTPUT_VARIABLE monomap_git_describe
    RESULT_VARIABLE monomap_git_result
    OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  if(monomap_git_result EQUAL 0 AND monomap_git_describe)
    set(MONOMAP_GIT_COMMIT "${monomap_git_describe}")
  endif()
endif()
set(MONOMAP_GENERATED_INCLUDE_DIR ${PROJECT_BINARY_DIR}/generated)
configure_file(${PROJECT_SOURCE_DIR}/cmake/version.h.in
               ${MONOMAP_GENERATED_INCLUDE_DIR}/monomap/version.h @ONLY)
