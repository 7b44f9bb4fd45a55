# CMake toolchain: cross build for the board (arm64, Debian bookworm) against the sysroot tests/arm64/setup.sh makes.
# The sysroot is ARM64_SYSROOT (cache variable or environment), by default <source>/build/arm64-sysroot. Test
# executables run under qemu-aarch64 with the sysroot as its library root, so ctest runs them transparently.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)

if(NOT ARM64_SYSROOT)
  set(ARM64_SYSROOT "$ENV{ARM64_SYSROOT}")
endif()
if(NOT ARM64_SYSROOT)
  get_filename_component(ARM64_SYSROOT "${CMAKE_CURRENT_LIST_DIR}/../../build/arm64-sysroot" ABSOLUTE)
endif()
if(NOT EXISTS "${ARM64_SYSROOT}/usr/include/aarch64-linux-gnu")
  message(FATAL_ERROR "No arm64 sysroot at ${ARM64_SYSROOT}: make it with tests/arm64/setup.sh")
endif()
set(ARM64_SYSROOT "${ARM64_SYSROOT}" CACHE PATH "arm64 sysroot (tests/arm64/setup.sh)")
# try_compile projects re-read this file without the main project's cache: hand the sysroot on to them.
list(APPEND CMAKE_TRY_COMPILE_PLATFORM_VARIABLES ARM64_SYSROOT)

set(CMAKE_SYSROOT "${ARM64_SYSROOT}")
set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)
set(CMAKE_LIBRARY_ARCHITECTURE aarch64-linux-gnu)

# Libraries, headers and CMake packages only from the sysroot; programs (pkg-config, dtc) from the host.
set(CMAKE_FIND_ROOT_PATH "${ARM64_SYSROOT}")
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)

# pkg-config: only the sysroot's .pc files, their paths re-rooted into the sysroot.
set(ENV{PKG_CONFIG_SYSROOT_DIR} "${ARM64_SYSROOT}")
set(ENV{PKG_CONFIG_LIBDIR} "${ARM64_SYSROOT}/usr/lib/aarch64-linux-gnu/pkgconfig:${ARM64_SYSROOT}/usr/share/pkgconfig")
set(ENV{PKG_CONFIG_PATH} "")

# The sysroot is the library root of the emulator (-L): never the host's /usr/aarch64-linux-gnu, which mixed with
# multiarch libraries makes qemu-aarch64 hang.
find_program(QEMU_AARCH64 NAMES qemu-aarch64 qemu-aarch64-static REQUIRED)
set(CMAKE_CROSSCOMPILING_EMULATOR "${QEMU_AARCH64};-L;${ARM64_SYSROOT}")
