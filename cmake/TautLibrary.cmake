# taut_add_layer(NAME DIR DEPS...): a static library from every .cc in DIR, with the project root
# (and, once installed, include/taut/detail) on its include path. Its headers are installed in
# include/taut/detail/DIR: users include the public set <taut/NAME.h>
# (cmake/TautPublicHeaders.cmake), not these.
function(taut_add_layer name dir)
  file(GLOB sources CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/${dir}/*.cc)
  file(GLOB headers CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/${dir}/*.h)
  add_library(${name} STATIC ${sources} ${headers})
  target_include_directories(${name} PUBLIC
    $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}>
    $<INSTALL_INTERFACE:include/taut/detail>)
  target_compile_options(${name} PRIVATE -Wall -Wextra)
  target_link_libraries(${name} PUBLIC ${ARGN})
  install(FILES ${headers} DESTINATION include/taut/detail/${dir})
endfunction()
