# Version check of the mechanica CMake package. The version is read from the installed
# mechanica.h (MECH_VERSION_MAJOR/MINOR/PATCH), so it is always the library's own. While the
# major version is 0, a request is met by the same minor version with a patch at least as
# high; from 1.0 on, by the same major version.

get_filename_component(_mechanica_header "${CMAKE_CURRENT_LIST_DIR}/../../../include/mechanica.h" ABSOLUTE)
set(PACKAGE_VERSION "0.0.0")
if(EXISTS "${_mechanica_header}")
    foreach(_part MAJOR MINOR PATCH)
        file(STRINGS "${_mechanica_header}" _line REGEX "^#define MECH_VERSION_${_part} [0-9]+")
        string(REGEX REPLACE "^#define MECH_VERSION_${_part} ([0-9]+).*" "\\1" _mechanica_${_part} "${_line}")
    endforeach()
    set(PACKAGE_VERSION "${_mechanica_MAJOR}.${_mechanica_MINOR}.${_mechanica_PATCH}")
endif()

set(PACKAGE_VERSION_COMPATIBLE FALSE)
set(PACKAGE_VERSION_EXACT FALSE)
if(NOT PACKAGE_FIND_VERSION)
    set(PACKAGE_VERSION_COMPATIBLE TRUE)
elseif(PACKAGE_VERSION VERSION_GREATER_EQUAL PACKAGE_FIND_VERSION)
    if(_mechanica_MAJOR EQUAL 0)
        if(PACKAGE_FIND_VERSION_MAJOR EQUAL 0 AND PACKAGE_FIND_VERSION_MINOR EQUAL _mechanica_MINOR)
            set(PACKAGE_VERSION_COMPATIBLE TRUE)
        endif()
    elseif(PACKAGE_FIND_VERSION_MAJOR EQUAL _mechanica_MAJOR)
        set(PACKAGE_VERSION_COMPATIBLE TRUE)
    endif()
endif()
if(PACKAGE_VERSION VERSION_EQUAL PACKAGE_FIND_VERSION)
    set(PACKAGE_VERSION_EXACT TRUE)
endif()

# A 32-bit build cannot use a 64-bit library or the reverse.
if(CMAKE_SIZEOF_VOID_P AND NOT CMAKE_SIZEOF_VOID_P EQUAL 8)
    set(PACKAGE_VERSION "${PACKAGE_VERSION} (64-bit)")
    set(PACKAGE_VERSION_UNSUITABLE TRUE)
endif()
unset(_mechanica_header)
