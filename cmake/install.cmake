# Install rules: the libraries, their public headers, the CLIs, a CMake package
# (find_package(crowddb) gives crowddb::crowddb and crowddb::sdf) and pkg-config files.
# Installed to CMAKE_INSTALL_PREFIX, or wherever `cmake --install build --prefix DIR` says:
# both the package and the .pc files find their files relative to themselves.
include(CMakePackageConfigHelpers)

install(TARGETS crowddb sdf EXPORT crowddbTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/crowddb ${PROJECT_SOURCE_DIR}/include/sdf
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
if(CROWDDB_BUILD_TOOLS)
  install(TARGETS crowddb_cli sdfsched_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  # With shared libraries the installed commands find them relative to themselves.
  if(BUILD_SHARED_LIBS)
    file(RELATIVE_PATH bin_to_lib /prefix/${CMAKE_INSTALL_BINDIR} /prefix/${CMAKE_INSTALL_LIBDIR})
    set_target_properties(crowddb_cli sdfsched_cli PROPERTIES INSTALL_RPATH "$ORIGIN/${bin_to_lib}")
  endif()
endif()

set(crowddb_cmake_dir ${CMAKE_INSTALL_LIBDIR}/cmake/crowddb)
install(EXPORT crowddbTargets NAMESPACE crowddb:: DESTINATION ${crowddb_cmake_dir})
configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/crowddbConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/crowddbConfig.cmake
                              INSTALL_DESTINATION ${crowddb_cmake_dir})
# 0.x: a package of another minor version is not compatible (the API may still change).
write_basic_package_version_file(${PROJECT_BINARY_DIR}/crowddbConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/crowddbConfig.cmake
              ${PROJECT_BINARY_DIR}/crowddbConfigVersion.cmake
        DESTINATION ${crowddb_cmake_dir})

# pkg-config: the prefix is found from the .pc file's own place (${pcfiledir}). A static library
# lists what it needs at link time in Libs/Requires; a shared one keeps that private.
file(RELATIVE_PATH crowddb_pc_to_prefix /prefix/${CMAKE_INSTALL_LIBDIR}/pkgconfig /prefix)
if(BUILD_SHARED_LIBS)
  set(crowddb_pc_requires "Requires.private: tbb sqlite3 pugixml gmpxx mpfr gmp")
  set(crowddb_pc_libs_private "Libs.private: -lRecast -lDetour -pthread")
  set(crowddb_pc_libs "")
  set(sdf_pc_requires "Requires.private: pugixml")
else()
  set(crowddb_pc_requires "Requires: tbb sqlite3 pugixml gmpxx mpfr gmp")
  set(crowddb_pc_libs_private "")
  set(crowddb_pc_libs " -lRecast -lDetour -pthread")
  set(sdf_pc_requires "Requires: pugixml")
endif()
foreach(pc crowddb crowddb-sdf)
  configure_file(${CMAKE_CURRENT_LIST_DIR}/${pc}.pc.in ${PROJECT_BINARY_DIR}/${pc}.pc @ONLY)
  install(FILES ${PROJECT_BINARY_DIR}/${pc}.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
endforeach()
