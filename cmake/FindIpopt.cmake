# Finds COIN-OR Ipopt through pkg-config and defines the imported target Ipopt::Ipopt.
find_package(PkgConfig QUIET)
if(PkgConfig_FOUND)
  pkg_check_modules(PC_IPOPT QUIET ipopt)
endif()
find_path(IPOPT_INCLUDE_DIR IpTNLP.hpp HINTS ${PC_IPOPT_INCLUDE_DIRS} PATH_SUFFIXES coin coin-or)
find_library(IPOPT_LIBRARY ipopt HINTS ${PC_IPOPT_LIBRARY_DIRS})
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(Ipopt REQUIRED_VARS IPOPT_LIBRARY IPOPT_INCLUDE_DIR)
if(Ipopt_FOUND AND NOT TARGET Ipopt::Ipopt)
  add_library(Ipopt::Ipopt UNKNOWN IMPORTED)
  set_target_properties(Ipopt::Ipopt PROPERTIES
    IMPORTED_LOCATION "${IPOPT_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${IPOPT_INCLUDE_DIR}"
    INTERFACE_COMPILE_DEFINITIONS "HAVE_CSTDDEF")
endif()
mark_as_advanced(IPOPT_INCLUDE_DIR IPOPT_LIBRARY)
