# Debian packages taut builds against (see README "Dependencies").
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(tinyobjloader REQUIRED)
find_package(PkgConfig REQUIRED)
if(TAUT_BULLET_FLOAT)
  pkg_check_modules(BULLET REQUIRED IMPORTED_TARGET bullet)
else()
  pkg_check_modules(BULLET REQUIRED IMPORTED_TARGET bullet-float64)
endif()
