# CHOLMOD as the imported target rfem::cholmod. SuiteSparse >= 7 ships SuiteSparse::CHOLMOD;
# Debian 12's 5.12 has neither a CMake config nor a pkg-config file.
find_package(CHOLMOD CONFIG QUIET)
if(TARGET SuiteSparse::CHOLMOD)
  add_library(rfem::cholmod INTERFACE IMPORTED)
  target_link_libraries(rfem::cholmod INTERFACE SuiteSparse::CHOLMOD)
  return()
endif()
find_path(CHOLMOD_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse REQUIRED)
find_library(CHOLMOD_LIBRARY cholmod REQUIRED)
find_library(SUITESPARSECONFIG_LIBRARY suitesparseconfig REQUIRED)
add_library(rfem::cholmod INTERFACE IMPORTED)
target_include_directories(rfem::cholmod INTERFACE ${CHOLMOD_INCLUDE_DIR})
target_link_libraries(rfem::cholmod INTERFACE ${CHOLMOD_LIBRARY} ${SUITESPARSECONFIG_LIBRARY})
