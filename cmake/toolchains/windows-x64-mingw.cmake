# Cross build for Windows x64 with MinGW-w64 (Debian: gcc-mingw-w64-x86-64,
# g++-mingw-w64-x86-64-posix; scripts/cross-build.sh windows-x64 installs
# them). The posix flavour of the compiler has the thread model libgomp
# needs. Programs built here run under wine (CMAKE_CROSSCOMPILING_EMULATOR),
# so ctest runs the tests under wine.
#
#   cmake -S . -B build-windows-x64 \
#         -DCMAKE_TOOLCHAIN_FILE=cmake/toolchains/windows-x64-mingw.cmake \
#         -DCMAKE_PREFIX_PATH=<prefix with a Windows libccd>
set(CMAKE_SYSTEM_NAME Windows)
set(CMAKE_SYSTEM_PROCESSOR AMD64)

set(WC_MINGW_TRIPLET x86_64-w64-mingw32)
set(CMAKE_C_COMPILER ${WC_MINGW_TRIPLET}-gcc-posix)
set(CMAKE_CXX_COMPILER ${WC_MINGW_TRIPLET}-g++-posix)
set(CMAKE_RC_COMPILER ${WC_MINGW_TRIPLET}-windres)

# Headers and libraries of the target only; programs of the host. Packages
# (CMake config files) are searched in CMAKE_PREFIX_PATH as given, where the
# cross build's own libccd is.
set(CMAKE_FIND_ROOT_PATH /usr/${WC_MINGW_TRIPLET})
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE BOTH)

find_program(WC_WINE NAMES wine wine64)
if(WC_WINE)
  set(CMAKE_CROSSCOMPILING_EMULATOR ${WC_WINE})
endif()
