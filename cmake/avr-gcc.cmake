# CMake toolchain file for Debian's AVR cross toolchain
# (packages gcc-avr, binutils-avr, avr-libc).
#
# Used by the top-level ExternalProject that builds firmware/; can also be
# used standalone:
#   cmake -S firmware -B /tmp/fw -DCMAKE_TOOLCHAIN_FILE=$PWD/cmake/avr-gcc.cmake
#
# The target is a bare-metal microcontroller: there is no OS, and nothing we
# build can run on the host, so CMake must never try to link-and-run a test
# program (try_run) or look for host libraries.

set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR avr)

# Debian installs the tools with the avr- prefix in /usr/bin.
find_program(AVR_GCC     avr-gcc     REQUIRED)
find_program(AVR_GXX     avr-g++)
find_program(AVR_OBJCOPY avr-objcopy REQUIRED)
find_program(AVR_OBJDUMP avr-objdump REQUIRED)
find_program(AVR_SIZE    avr-size    REQUIRED)
find_program(AVR_NM      avr-nm      REQUIRED)

set(CMAKE_C_COMPILER   ${AVR_GCC})
set(CMAKE_ASM_COMPILER ${AVR_GCC})
if(AVR_GXX)
  set(CMAKE_CXX_COMPILER ${AVR_GXX})
endif()

# Make CMake's own binutils lookup agree with ours (it would otherwise fall
# back to the host's objcopy/objdump when it cannot infer the prefix).
set(CMAKE_OBJCOPY ${AVR_OBJCOPY} CACHE FILEPATH "avr-objcopy" FORCE)
set(CMAKE_OBJDUMP ${AVR_OBJDUMP} CACHE FILEPATH "avr-objdump" FORCE)
set(CMAKE_SIZE    ${AVR_SIZE}    CACHE FILEPATH "avr-size"    FORCE)
set(CMAKE_NM      ${AVR_NM}      CACHE FILEPATH "avr-nm"      FORCE)

# Compiler checks only compile (a static library): linking a test program
# would need an -mmcu, and running one is impossible on the host.
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)

# Headers and libraries come from avr-libc's sysroot-like tree, programs
# from the host.
set(CMAKE_FIND_ROOT_PATH /usr/lib/avr)
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
