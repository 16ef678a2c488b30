# Debian packages taut builds against (see README "Dependencies").
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(tinyobjloader REQUIRED)
find_package(PkgConfig REQUIRED)
if(TAUT_BULLET_FLOAT)
  pkg_check_modules(BULLET REQUIRED IMPORTED_TARGET bullet)
else()
  pkg_check_modules(BULLET REQUIRED IMPORTED_TARGET bullet-float64)
endif()
# METIS (Apache-2.0, Debian libmetis-dev): the nested-dissection ordering of large bodies
# factorizations (plugin/nested_dissection.h). Debian ships no CMake or pkg-config file for it, so
# METIS::METIS is made from the header and the library; tautConfig.cmake.in repeats this.
if(NOT TARGET METIS::METIS)
  find_path(METIS_INCLUDE_DIR metis.h REQUIRED)
  find_library(METIS_LIBRARY metis REQUIRED)
  add_library(METIS::METIS UNKNOWN IMPORTED)
  set_target_properties(METIS::METIS PROPERTIES
    IMPORTED_LOCATION ${METIS_LIBRARY}
    INTERFACE_INCLUDE_DIRECTORIES ${METIS_INCLUDE_DIR})
endif()
# CHOLMOD (SuiteSparse), only with -DTAUT_WITH_CHOLMOD=ON: the supernodal Cholesky of large bodies
# (plugin/cholmod_cholesky.h). Its supernodal module is GPL-2+, so a build with it is GPL-bound;
# the default build neither finds nor links it (README "License").
# SuiteSparse >= 7 ships a CMake package with SuiteSparse::CHOLMOD; Debian 12's 5.12 ships only
# the header (suitesparse/cholmod.h) and libcholmod.so, so the same target is made from them.
# tautConfig.cmake.in repeats this for consumers of the installed package.
if(TAUT_WITH_CHOLMOD)
  find_package(CHOLMOD CONFIG QUIET)
  if(NOT TARGET SuiteSparse::CHOLMOD)
    find_path(CHOLMOD_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse REQUIRED)
    find_library(CHOLMOD_LIBRARY cholmod REQUIRED)
    add_library(SuiteSparse::CHOLMOD UNKNOWN IMPORTED)
    set_target_properties(SuiteSparse::CHOLMOD PROPERTIES
      IMPORTED_LOCATION ${CHOLMOD_LIBRARY}
      INTERFACE_INCLUDE_DIRECTORIES ${CHOLMOD_INCLUDE_DIR})
  endif()
endif()
