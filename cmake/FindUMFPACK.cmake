# FindUMFPACK: the UMFPACK sparse LU of SuiteSparse (Debian: libsuitesparse-dev).
# Defines UMFPACK::UMFPACK (include directory and libraries umfpack, amd, suitesparseconfig).
find_path(UMFPACK_INCLUDE_DIR umfpack.h PATH_SUFFIXES suitesparse)
find_library(UMFPACK_LIBRARY umfpack)
find_library(AMD_LIBRARY amd)
find_library(SUITESPARSECONFIG_LIBRARY suitesparseconfig)
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(UMFPACK REQUIRED_VARS UMFPACK_INCLUDE_DIR UMFPACK_LIBRARY AMD_LIBRARY SUITESPARSECONFIG_LIBRARY)
if(UMFPACK_FOUND AND NOT TARGET UMFPACK::UMFPACK)
  add_library(UMFPACK::UMFPACK INTERFACE IMPORTED)
  set_target_properties(UMFPACK::UMFPACK PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES "${UMFPACK_INCLUDE_DIR}"
    INTERFACE_LINK_LIBRARIES "${UMFPACK_LIBRARY};${AMD_LIBRARY};${SUITESPARSECONFIG_LIBRARY}")
endif()
mark_as_advanced(UMFPACK_INCLUDE_DIR UMFPACK_LIBRARY AMD_LIBRARY SUITESPARSECONFIG_LIBRARY)
