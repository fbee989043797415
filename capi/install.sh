#!/usr/bin/env bash
# Builds the C API and lays it out under a prefix for find_package(situ):
#
#   bash capi/install.sh PREFIX            # the debug build
#   PROFILE=release bash capi/install.sh PREFIX
#   SITU_LIB_DIR=target/debug/deps bash capi/install.sh PREFIX   # libraries built already
#
# With SITU_LIB_DIR it builds nothing and takes libsitu.so and libsitu.a
# from that folder (capi/tests/c_programs.rs: the libraries `cargo test`
# built in target/debug/deps, with the features of its run).
# PREFIX/include/situ.h, PREFIX/lib/libsitu.so, PREFIX/lib/libsitu.a,
# PREFIX/lib/cmake/situ/situConfig.cmake and situConfigVersion.cmake.
# A C or C++ project then configures with -DCMAKE_PREFIX_PATH=PREFIX.
set -euo pipefail

if [ $# -ne 1 ]; then
    echo "usage: capi/install.sh PREFIX" >&2
    exit 2
fi
prefix="$1"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
profile="${PROFILE:-debug}"
if [ -n "${SITU_LIB_DIR:-}" ]; then
    target="$SITU_LIB_DIR"
    profile="prebuilt in $target"
else
    case "$profile" in
    debug) (cd "$root" && cargo build --quiet -p situ-capi) ;;
    release) (cd "$root" && cargo build --quiet --release -p situ-capi) ;;
    *) echo "capi/install.sh: error: PROFILE is debug or release, not $profile" >&2; exit 2 ;;
    esac
    target="${CARGO_TARGET_DIR:-$root/target}/$profile"
fi
for lib in libsitu.so libsitu.a; do
    if [ ! -f "$target/$lib" ]; then
        echo "capi/install.sh: error: $target/$lib is missing" >&2
        exit 1
    fi
done
version="$(sed -n 's/^version = "\(.*\)"/\1/p' "$root/Cargo.toml" | head -n 1)"

mkdir -p "$prefix/include" "$prefix/lib/cmake/situ"
install -m 644 "$root/capi/include/situ.h" "$prefix/include/situ.h"
install -m 755 "$target/libsitu.so" "$prefix/lib/libsitu.so"
install -m 644 "$target/libsitu.a" "$prefix/lib/libsitu.a"
install -m 644 "$root/capi/cmake/situConfig.cmake" "$prefix/lib/cmake/situ/situConfig.cmake"
cat >"$prefix/lib/cmake/situ/situConfigVersion.cmake" <<CMAKE
# situ $version: find_package(situ X.Y) accepts it when X.Y is not newer.
set(PACKAGE_VERSION "$version")
if(PACKAGE_FIND_VERSION VERSION_GREATER PACKAGE_VERSION)
  set(PACKAGE_VERSION_COMPATIBLE FALSE)
else()
  set(PACKAGE_VERSION_COMPATIBLE TRUE)
  if(PACKAGE_FIND_VERSION STREQUAL PACKAGE_VERSION)
    set(PACKAGE_VERSION_EXACT TRUE)
  endif()
endif()
CMAKE
echo "capi/install.sh: situ $version ($profile) installed in $prefix" >&2
