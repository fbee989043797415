# find_package(situ): the C API of situ (docs/c.md), laid out by
# capi/install.sh PREFIX as PREFIX/include/situ.h, PREFIX/lib/libsitu.so,
# PREFIX/lib/libsitu.a and this file in PREFIX/lib/cmake/situ/.
#
#   find_package(situ REQUIRED)
#   target_link_libraries(node PRIVATE situ::situ)         # libsitu.so
#   target_link_libraries(node PRIVATE situ::situ_static)  # libsitu.a
get_filename_component(_situ_prefix "${CMAKE_CURRENT_LIST_DIR}/../../.." ABSOLUTE)

foreach(_situ_file include/situ.h lib/libsitu.so lib/libsitu.a)
  if(NOT EXISTS "${_situ_prefix}/${_situ_file}")
    set(situ_FOUND FALSE)
    set(situ_NOT_FOUND_MESSAGE "situ: ${_situ_prefix}/${_situ_file} is missing; run capi/install.sh ${_situ_prefix}")
    return()
  endif()
endforeach()

if(NOT TARGET situ::situ)
  add_library(situ::situ SHARED IMPORTED)
  set_target_properties(situ::situ PROPERTIES
    IMPORTED_LOCATION "${_situ_prefix}/lib/libsitu.so"
    IMPORTED_SONAME "libsitu.so"
    INTERFACE_INCLUDE_DIRECTORIES "${_situ_prefix}/include")
endif()

if(NOT TARGET situ::situ_static)
  add_library(situ::situ_static STATIC IMPORTED)
  # The system libraries Rust's standard library needs
  # (`cargo rustc -p situ-capi --crate-type staticlib -- --print native-static-libs`).
  set_target_properties(situ::situ_static PROPERTIES
    IMPORTED_LOCATION "${_situ_prefix}/lib/libsitu.a"
    INTERFACE_INCLUDE_DIRECTORIES "${_situ_prefix}/include"
    INTERFACE_LINK_LIBRARIES "gcc_s;util;rt;pthread;m;dl;c")
endif()

set(situ_FOUND TRUE)
unset(_situ_prefix)
unset(_situ_file)
