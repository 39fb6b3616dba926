# Installation and the exported package: `find_package(monomap)` gives
# monomap::<module> (monomap::io, monomap::sim, ...) with include dirs and
# dependencies, and monomap.pc serves pkg-config users. See docs/install.md.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(MONOMAP_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/monomap)

# Every module library that exists in this build, in dependency order.
set(monomap_export_targets "")
foreach(module ${MONOMAP_MODULES})
  if(TARGET monomap_${module})
    set_target_properties(monomap_${module} PROPERTIES EXPORT_NAME ${module})
    list(APPEND monomap_export_targets monomap_${module})
  endif()
endforeach()

install(TARGETS ${monomap_export_targets}
        EXPORT monomapTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
if(TARGET monomap)
  install(TARGETS monomap RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()
# Public headers, without the helpers of the tests.
install(DIRECTORY ${PROJECT_SOURCE_DIR}/src/monomap
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
        FILES_MATCHING PATTERN "*.h"
        PATTERN "test_scene.h" EXCLUDE
        PATTERN "*for_tests.h" EXCLUDE
        PATTERN "exe" EXCLUDE)
install(FILES ${MONOMAP_GENERATED_INCLUDE_DIR}/monomap/version.h
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/monomap)

install(EXPORT monomapTargets NAMESPACE monomap::
        DESTINATION ${MONOMAP_CMAKE_DIR})
configure_package_config_file(
  ${PROJECT_SOURCE_DIR}/cmake/monomapConfig.cmake.in
  ${PROJECT_BINARY_DIR}/monomapConfig.cmake
  INSTALL_DESTINATION ${MONOMAP_CMAKE_DIR})
write_basic_package_version_file(
  ${PROJECT_BINARY_DIR}/monomapConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/monomapConfig.cmake
              ${PROJECT_BINARY_DIR}/monomapConfigVersion.cmake
        DESTINATION ${MONOMAP_CMAKE_DIR})

# pkg-config: the static libraries, highest module first, so a plain
# linker command resolves them in one pass.
set(MONOMAP_PC_LIBS "")
foreach(target ${monomap_export_targets})
  get_target_property(type ${target} TYPE)
  if(type STREQUAL "STATIC_LIBRARY")
    set(MONOMAP_PC_LIBS "-l${target} ${MONOMAP_PC_LIBS}")
  endif()
endforeach()
# Relocatable: the prefix is found from the .pc file's own folder, so
# `cmake --install --prefix DIR` gives a working file.
file(RELATIVE_PATH MONOMAP_PC_PREFIX_FROM_PCFILEDIR
     /${CMAKE_INSTALL_LIBDIR}/pkgconfig /)
configure_file(${PROJECT_SOURCE_DIR}/cmake/monomap.pc.in
               ${PROJECT_BINARY_DIR}/monomap.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/monomap.pc
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)

# Man page from `monomap --help` by Debian's help2man, when installed.
find_program(HELP2MAN_EXECUTABLE help2man)
if(HELP2MAN_EXECUTABLE AND TARGET monomap)
  set(monomap_man ${PROJECT_BINARY_DIR}/man/monomap.1)
  add_custom_command(
    OUTPUT ${monomap_man}
    COMMAND ${CMAKE_COMMAND} -E make_directory ${PROJECT_BINARY_DIR}/man
    COMMAND bash ${PROJECT_SOURCE_DIR}/scripts/man_subcommands.sh
            $<TARGET_FILE:monomap> ${PROJECT_BINARY_DIR}/man/subcommands.h2m
    COMMAND ${HELP2MAN_EXECUTABLE} --no-info --version-option=--version
            "--name=dense planar maps and localization from one camera and odometry" --include=${PROJECT_BINARY_DIR}/man/subcommands.h2m
            --output=${monomap_man}
            $<TARGET_FILE:monomap>
    DEPENDS monomap ${PROJECT_SOURCE_DIR}/scripts/man_subcommands.sh
    COMMENT "Generating the monomap(1) man page with help2man"
    VERBATIM)
  add_custom_target(man ALL DEPENDS ${monomap_man})
  install(FILES ${monomap_man} DESTINATION ${CMAKE_INSTALL_MANDIR}/man1)
else()
  message(STATUS "help2man not found: no man page (apt-get install help2man)")
endif()
