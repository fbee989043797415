#!/usr/bin/env bash
# Installs what the C API's tests need when a command is missing (Debian's
# packages): CMake, gcc, g++ and valgrind. capi/tests/c_programs.rs builds
# the C test and the C++ example node with CMake through find_package(situ)
# and runs them under valgrind.
set -euo pipefail
exec bash "$(dirname "$0")/apt-install.sh" cmake=cmake gcc=gcc g++=g++ valgrind=valgrind
