# dynid_kdl_bridge: Orocos KDL behind an Eigen-free interface (tests/oracle/kdl_bridge.hpp), used
# by oracle_tests and bench/dynamics_bench. Debian's KDL is built for plain x86-64 and passes Eigen
# objects through its API; under the `native` preset dynid's Eigen aligns its heap blocks to
# 32/64 bytes by its own allocator, so a JntArray made on one side and freed on the other corrupts
# the heap (docs/design.md section 1). The bridge is therefore
# - compiled without the native flags, so its Eigen agrees with KDL's;
# - a SHARED library with hidden symbols: its Eigen template instances (compiled without AVX)
#   stay inside it, where a static library would let the linker merge them (COMDAT) with the
#   native objects' instances of the same templates (one definition for two different codes).
include_guard(GLOBAL)

find_package(orocos_kdl REQUIRED)
# kdl_parser's CMake config pulls in ROS 2's ament (which needs Python modules), so the library
# is found directly.
find_library(KDL_PARSER_LIBRARY kdl_parser REQUIRED)
find_path(KDL_PARSER_INCLUDE_DIR kdl_parser/kdl_parser.hpp REQUIRED)

add_library(dynid_kdl_bridge SHARED ${PROJECT_SOURCE_DIR}/tests/oracle/kdl_bridge.cpp)
set_target_properties(dynid_kdl_bridge PROPERTIES
  CXX_VISIBILITY_PRESET hidden VISIBILITY_INLINES_HIDDEN ON
  LIBRARY_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/lib)
get_target_property(dynid_kdl_bridge_options dynid_kdl_bridge COMPILE_OPTIONS)
if(DYNID_NATIVE_OPTIONS)
  list(REMOVE_ITEM dynid_kdl_bridge_options ${DYNID_NATIVE_OPTIONS})
  set_property(TARGET dynid_kdl_bridge PROPERTY COMPILE_OPTIONS ${dynid_kdl_bridge_options})
endif()
target_include_directories(dynid_kdl_bridge PUBLIC ${PROJECT_SOURCE_DIR}/tests)
target_include_directories(dynid_kdl_bridge SYSTEM PRIVATE
  ${orocos_kdl_INCLUDE_DIRS} ${KDL_PARSER_INCLUDE_DIR})
target_link_libraries(dynid_kdl_bridge PRIVATE Eigen3::Eigen ${orocos_kdl_LIBRARIES}
  ${KDL_PARSER_LIBRARY})

# Links `target` to the bridge, keeping the executable's Eigen symbols out of its dynamic symbol
# table (cmake/hide_eigen.map says why).
function(dynid_link_kdl_bridge target)
  target_link_libraries(${target} PRIVATE dynid_kdl_bridge)
  target_link_options(${target} PRIVATE
    "-Wl,--version-script=${PROJECT_SOURCE_DIR}/cmake/hide_eigen.map")
  set_property(TARGET ${target} APPEND PROPERTY LINK_DEPENDS ${PROJECT_SOURCE_DIR}/cmake/hide_eigen.map)
endfunction()
