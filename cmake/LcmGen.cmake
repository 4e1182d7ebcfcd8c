# Debian's LCM 1.3.1 ships no CMake package: run lcm-gen --cpp into the build tree ourselves.
find_program(LCM_GEN lcm-gen REQUIRED)
find_path(LCM_INCLUDE_DIR lcm/lcm-cpp.hpp REQUIRED)
find_library(LCM_LIBRARY lcm REQUIRED)

# lcm_generate_cpp(<target> <package> <lcm files...>): an INTERFACE target whose include
# directory holds <package>/<type>.hpp for every file.
function(lcm_generate_cpp target package)
  set(out_dir ${CMAKE_CURRENT_BINARY_DIR}/lcmtypes)
  set(headers)
  foreach(lcm_file ${ARGN})
    get_filename_component(abs ${lcm_file} ABSOLUTE)
    get_filename_component(type ${lcm_file} NAME_WE)
    set(header ${out_dir}/${package}/${type}.hpp)
    add_custom_command(
      OUTPUT ${header}
      COMMAND ${LCM_GEN} --cpp --cpp-hpath ${out_dir} ${abs}
      DEPENDS ${abs}
      COMMENT "lcm-gen ${type}")
    list(APPEND headers ${header})
  endforeach()
  add_custom_target(${target}_gen DEPENDS ${headers})
  add_library(${target} INTERFACE)
  add_dependencies(${target} ${target}_gen)
  target_include_directories(${target} INTERFACE ${out_dir} ${LCM_INCLUDE_DIR})
  target_link_libraries(${target} INTERFACE ${LCM_LIBRARY})
endfunction()
