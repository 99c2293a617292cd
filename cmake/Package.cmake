# The Debian package: `cmake --build build --target deb` builds what the
# package holds (the CLI, the fuzz targets; never the tests) and runs
# `cpack -G DEB`; `cpack -G DEB` alone packages a tree where those are built.
#
# One .deb of the components cli, fuzz, docs and examples, stripped, its
# Depends computed from the binaries by dpkg-shlibdeps (dpkg-dev), checked
# by lintian in ci/package-test.

# `install` (and so cpack's preinstall step) must not build `all`: that is
# the whole test suite. What a component needs is built by its own target.
set(CMAKE_SKIP_INSTALL_ALL_DEPENDENCY TRUE)

include(GNUInstallDirs)

# The package's maintainer: whoever builds and publishes it says who they
# are (-DAVRBENCH_MAINTAINER="Name <address>"). The default is the project's
# no-reply placeholder, which lintian accepts; a published package must set it.
set(AVRBENCH_MAINTAINER "avrbench developers <maintainers@users.noreply.h-seed-cd087d80.example>" CACHE STRING
    "the .deb's Maintainer field and changelog signature")

# A clear word when the package is made from a tree that has not built the CLI.
install(CODE "
  if(NOT EXISTS \"$<TARGET_FILE:avrbench>\")
    message(FATAL_ERROR \"avrbench is not built in ${CMAKE_BINARY_DIR}: cmake --build ${CMAKE_BINARY_DIR} --target avrbench (or --target deb)\")
  endif()" COMPONENT cli)

# Debian's doc files: copyright, and the changelog of a native package,
# compressed as policy 12.7 asks (gzip -9n: no name or time stamp, so the
# same bytes every build).
set(AVRBENCH_PACKAGE_DOC ${CMAKE_BINARY_DIR}/package-doc)
file(MAKE_DIRECTORY ${AVRBENCH_PACKAGE_DOC})
configure_file(${CMAKE_SOURCE_DIR}/cmake/package/changelog.in ${AVRBENCH_PACKAGE_DOC}/changelog @ONLY)
execute_process(COMMAND gzip -9nf ${AVRBENCH_PACKAGE_DOC}/changelog RESULT_VARIABLE gzip_result)
if(NOT gzip_result EQUAL 0)
  message(FATAL_ERROR "gzip of ${AVRBENCH_PACKAGE_DOC}/changelog failed")
endif()
install(FILES ${CMAKE_SOURCE_DIR}/cmake/package/copyright ${AVRBENCH_PACKAGE_DOC}/changelog.gz
        DESTINATION ${CMAKE_INSTALL_DOCDIR} COMPONENT cli)
# The manual page, compressed the same way.
configure_file(${CMAKE_SOURCE_DIR}/cmake/package/avrbench.1 ${AVRBENCH_PACKAGE_DOC}/avrbench.1 COPYONLY)
execute_process(COMMAND gzip -9nf ${AVRBENCH_PACKAGE_DOC}/avrbench.1 RESULT_VARIABLE gzip_result)
if(NOT gzip_result EQUAL 0)
  message(FATAL_ERROR "gzip of ${AVRBENCH_PACKAGE_DOC}/avrbench.1 failed")
endif()
install(FILES ${AVRBENCH_PACKAGE_DOC}/avrbench.1.gz DESTINATION ${CMAKE_INSTALL_MANDIR}/man1 COMPONENT cli)

# Stripped as dh_strip does: the .comment and .note sections go too (lintian:
# binary-has-unneeded-section). cmake_install.cmake calls CMAKE_STRIP.
set(CMAKE_STRIP ${CMAKE_SOURCE_DIR}/cmake/package/strip-for-debian CACHE FILEPATH "strip for the package" FORCE)

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME avrbench)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_CONTACT "${AVRBENCH_MAINTAINER}")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "cycle-level test bench for AVR firmware, on simavr")
# The long description: CPack puts the summary first and indents these lines.
set(CPACK_PACKAGE_DESCRIPTION "avrbench runs an unmodified AVR firmware ELF in simavr with virtual
hardware on its pins (stepper drivers and motors, limit switches, heaters
and thermistors, servos, serial hosts that stream G-code), records every
pin edge and serial byte with its cycle, writes VCD and HTML reports,
compares runs against golden timelines in CI and fuzzes G-code against the
emulated board.")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_STRIP_FILES ON)
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_COMPONENTS_GROUPING ALL_COMPONENTS_IN_ONE)
set(CPACK_COMPONENTS_ALL cli fuzz docs examples)
if(TARGET _avrbench)
  # The Python module in /usr/lib/python3/dist-packages: built for Debian's python3 (3.11).
  list(APPEND CPACK_COMPONENTS_ALL python)
  math(EXPR avrbench_python_next "${Python_VERSION_MINOR} + 1")
  set(CPACK_DEBIAN_PACKAGE_DEPENDS "python3 (>= ${Python_VERSION_MAJOR}.${Python_VERSION_MINOR}), python3 (<< ${Python_VERSION_MAJOR}.${avrbench_python_next})")
endif()
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION electronics)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
set(CPACK_DEBIAN_COMPRESSION_TYPE xz)
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION TRUE)
# Libraries: from the binaries (dpkg-shlibdeps). Programs the CLI starts:
# `avrbench fuzz --engine afl` runs afl-fuzz; the firmware a user tests is
# built with Debian's AVR toolchain, which avrbench itself never calls.
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "gcc-avr, avr-libc, binutils-avr, python3-numpy, python3-pytest")
set(CPACK_DEBIAN_PACKAGE_SUGGESTS "afl++, gtkwave, sigrok-cli, gdb-avr")
include(CPack)

add_custom_target(deb
  COMMAND ${CMAKE_CPACK_COMMAND} -G DEB --config ${CMAKE_BINARY_DIR}/CPackConfig.cmake
  WORKING_DIRECTORY ${CMAKE_BINARY_DIR}
  COMMENT "cpack -G DEB: the CLI, the fuzz targets, docs and examples"
  USES_TERMINAL)
add_dependencies(deb avrbench)
if(TARGET _avrbench)
  add_dependencies(deb _avrbench)
endif()
if(TARGET avrbench_fuzzers)
  add_dependencies(deb avrbench_fuzzers)
endif()
