# libsumo ships headers and libsumocpp.so but no CMake config: make an
# imported target from what the Debian `sumo` package installs.
find_path(LIBSUMO_INCLUDE_DIR libsumo/libsumo.h
          HINTS $ENV{SUMO_HOME}/include /usr/include /usr/local/include)
find_library(LIBSUMO_LIBRARY NAMES sumocpp
             HINTS $ENV{SUMO_HOME}/lib /usr/lib/x86_64-linux-gnu /usr/local/lib)
find_program(SUMO_NETCONVERT netconvert REQUIRED)
find_program(SUMO_NETGENERATE netgenerate REQUIRED)
if(NOT LIBSUMO_INCLUDE_DIR OR NOT LIBSUMO_LIBRARY)
  message(FATAL_ERROR "libsumo not found (libsumo/libsumo.h, libsumocpp.so): "
                      "install the Debian package `sumo` (scripts/setup.sh)")
endif()
add_library(libsumo::libsumo SHARED IMPORTED)
set_target_properties(libsumo::libsumo PROPERTIES
  IMPORTED_LOCATION ${LIBSUMO_LIBRARY}
  INTERFACE_INCLUDE_DIRECTORIES ${LIBSUMO_INCLUDE_DIR})
message(STATUS "libsumo: ${LIBSUMO_LIBRARY}")
