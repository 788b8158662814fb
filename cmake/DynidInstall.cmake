# Installation and packaging (issue 29, README "Install"):
#   cmake --install build --prefix P   the CLI (bin/dynid), the shared library libdynid.so, the
#                                      public headers, the built-in robots (share/dynid/robots),
#                                      the CMake package dynid (dynid::dynid) and dynid.pc;
#   cpack -G DEB (in build/)           the same as a Debian package.
# In a parent project (add_subdirectory(dynid)), dynid::dynid is the build tree's static library,
# and nothing of dynid is installed or packaged unless the parent sets DYNID_INSTALL.
include_guard(GLOBAL)
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

add_library(dynid::dynid ALIAS dynid_lib)
# dladdr (src/model/robots.cpp): in libc since glibc 2.34, in libdl before.
target_link_libraries(dynid_lib PRIVATE ${CMAKE_DL_LIBS})

option(DYNID_INSTALL "Install rules, the shared library, CMake package, pkg-config and CPack"
  ${PROJECT_IS_TOP_LEVEL})
if(NOT DYNID_INSTALL)
  return()
endif()

set(DYNID_ROBOTS_INSTALL_DIR ${CMAKE_INSTALL_DATADIR}/dynid/robots)
set(DYNID_CMAKE_INSTALL_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/dynid)

install(TARGETS dynid RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/dynid ${PROJECT_SOURCE_DIR}/include/compat/dynid
  DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} FILES_MATCHING PATTERN "*.hpp")
install(FILES ${PROJECT_BINARY_DIR}/generated/dynid/version.hpp
  DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/dynid)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/examples/robots/ DESTINATION ${DYNID_ROBOTS_INSTALL_DIR})

# The installed library is shared: the static dynid_lib links Ceres, NLopt, MuJoCo, urdfdom,
# yaml-cpp, tinyxml2, sqlite3, bz2 and lz4 privately, and a consumer of a static archive would
# have to find every one of them. libdynid.so carries them, and its users need only what the
# public headers include: Eigen and nlohmann-json. It is linked from dynid_lib's objects (no second
# compilation). Not in sanitizer builds, which are never installed.
if(CMAKE_CXX_FLAGS MATCHES "sanitize")
  return()
endif()
set_target_properties(dynid_lib PROPERTIES POSITION_INDEPENDENT_CODE ON)
add_library(dynid_shared SHARED $<TARGET_OBJECTS:dynid_lib>)
get_target_property(dynid_lib_links dynid_lib LINK_LIBRARIES)
target_link_libraries(dynid_shared
  PUBLIC Eigen3::Eigen nlohmann_json::nlohmann_json Threads::Threads
  PRIVATE ${dynid_lib_links})
target_include_directories(dynid_shared INTERFACE $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
target_compile_features(dynid_shared INTERFACE cxx_std_17)
# --exclude-libs: the static archives linked in (libceres.a) keep their symbols to themselves, so
# that a program that links its own Ceres gets its own. hide_eigen.map: dynid's Eigen template
# instances stay inside the library (under the native preset they are compiled with AVX and must
# not bind to a consumer's plain x86-64 ones, nor the reverse).
target_link_options(dynid_shared PRIVATE -Wl,--no-undefined -Wl,--exclude-libs,ALL
  "-Wl,--version-script=${PROJECT_SOURCE_DIR}/cmake/hide_eigen.map")
set_property(TARGET dynid_shared APPEND PROPERTY LINK_DEPENDS
  ${PROJECT_SOURCE_DIR}/cmake/hide_eigen.map)
set_target_properties(dynid_shared PROPERTIES OUTPUT_NAME dynid EXPORT_NAME dynid
  VERSION ${PROJECT_VERSION} SOVERSION ${PROJECT_VERSION_MAJOR}.${PROJECT_VERSION_MINOR})

install(TARGETS dynid_shared EXPORT dynidTargets
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(EXPORT dynidTargets NAMESPACE dynid:: DESTINATION ${DYNID_CMAKE_INSTALL_DIR})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/dynidConfig.cmake.in
  ${PROJECT_BINARY_DIR}/dynidConfig.cmake INSTALL_DESTINATION ${DYNID_CMAKE_INSTALL_DIR}
  PATH_VARS DYNID_ROBOTS_INSTALL_DIR)
# 0.x: a minor release may change the API.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/dynidConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/dynidConfig.cmake ${PROJECT_BINARY_DIR}/dynidConfigVersion.cmake
  DESTINATION ${DYNID_CMAKE_INSTALL_DIR})

# pkg-config: prefix relative to the .pc file, so that a moved prefix still works.
file(RELATIVE_PATH DYNID_PC_TO_PREFIX /p/${CMAKE_INSTALL_LIBDIR}/pkgconfig /p)
string(REGEX REPLACE "/$" "" DYNID_PC_TO_PREFIX "${DYNID_PC_TO_PREFIX}")
configure_file(${PROJECT_SOURCE_DIR}/cmake/dynid.pc.in ${PROJECT_BINARY_DIR}/dynid.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/dynid.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)

# cpack -G DEB: one package, the library and the CLI (the Python module installs with pip).
set(CPACK_PACKAGE_NAME dynid)
set(CPACK_PACKAGE_VENDOR "dynid")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
  "Identification of robot dynamic models (link inertias, actuator inertias, friction, payload)")
set(CPACK_PACKAGE_CONTACT "dynid maintainers <dynid@localhost>")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
# The shared libraries the CLI and libdynid.so load (dpkg-shlibdeps), and the headers that the
# public headers include.
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_DEPENDS "libeigen3-dev (>= 3.4), nlohmann-json3-dev")
set(CPACK_GENERATOR DEB)
include(CPack)
