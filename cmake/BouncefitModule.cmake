# A module folder holds a core library (its *.cc, tests excluded) with no LCM, V4L2 or
# terminal code, and optionally node/ with the thin LCM adapters around that core.
#
# bouncefit_module(<name> DEPS <targets...> [NODE_DEPS <targets...>])
#   defines bouncefit_<name> and, when node/ has sources, bouncefit_<name>_node.
function(bouncefit_module name)
  cmake_parse_arguments(M "" "" "DEPS;NODE_DEPS" ${ARGN})
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
  file(GLOB node_sources CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/node/*.cc)
  if(node_sources)
    add_library(bouncefit_${name}_node STATIC ${node_sources})
    target_link_libraries(bouncefit_${name}_node PUBLIC bouncefit_${name} bouncefit_msgs ${M_NODE_DEPS})
  endif()
endfunction()
