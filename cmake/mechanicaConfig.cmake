# CMake package of the mechanica C library, installed by `cargo cinstall -p mechanica` into
# <prefix>/share/mechanica/cmake next to the pkg-config file's prefix. Defines the imported
# target mechanica::mechanica: the shared library, with include/mechanica.h and the C++17
# header include/mechanica.hpp on its include path.
#
#   find_package(mechanica CONFIG REQUIRED)
#   target_link_libraries(app PRIVATE mechanica::mechanica)

get_filename_component(_mechanica_prefix "${CMAKE_CURRENT_LIST_DIR}/../../.." ABSOLUTE)

find_library(MECHANICA_LIBRARY
    NAMES mechanica
    HINTS "${_mechanica_prefix}"
    PATH_SUFFIXES lib lib64 "lib/${CMAKE_LIBRARY_ARCHITECTURE}"
    NO_DEFAULT_PATH)
set(_mechanica_include "${_mechanica_prefix}/include")

if(NOT MECHANICA_LIBRARY OR NOT EXISTS "${_mechanica_include}/mechanica.h")
    set(mechanica_FOUND FALSE)
    set(mechanica_NOT_FOUND_MESSAGE
        "libmechanica or mechanica.h is missing under ${_mechanica_prefix} (installed by cargo cinstall -p mechanica)")
    return()
endif()

if(NOT TARGET mechanica::mechanica)
    add_library(mechanica::mechanica SHARED IMPORTED)
    set_target_properties(mechanica::mechanica PROPERTIES
        IMPORTED_LOCATION "${MECHANICA_LIBRARY}"
        INTERFACE_INCLUDE_DIRECTORIES "${_mechanica_include}")
endif()

set(mechanica_INCLUDE_DIR "${_mechanica_include}")
unset(_mechanica_include)
unset(_mechanica_prefix)
