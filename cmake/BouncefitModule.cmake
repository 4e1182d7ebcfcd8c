# A module folder holds its library: its *.cc, tests excluded. No LCM outside pipeline/, no
# V4L2 outside capture/'s camera code, no terminal output (docs/DEVELOPING.md "Layout").
#
# bouncefit_module(<name> DEPS <targets...>) defines bouncefit_<name>.
function(bouncefit_module name)
  cmake_parse_arguments(M "" "" "DEPS" ${ARGN})
  file(GLOB core_sources CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/*.cc)
  list(FILTER core_sources EXCLUDE REGEX "_test\\.cc$")
  if(core_sources)
    add_library(bouncefit_${name} STATIC ${core_sources})
    target_include_directories(bouncefit_${name} PUBLIC ${PROJECT_SOURCE_DIR})
    target_link_libraries(bouncefit_${name} PUBLIC ${M_DEPS})
  else()
    add_library(bouncefit_${name} INTERFACE)
    target_include_directories(bouncefit_${name} INTERFACE ${PROJECT_SOURCE_DIR})
    target_link_libraries(bouncefit_${name} INTERFACE ${M_DEPS})
  endif()
endfunction()
