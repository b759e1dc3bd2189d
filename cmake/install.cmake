# `cmake --install`: the public headers, the libraries, the meshcast program
# (when built), a CMake package (find_package(meshcast CONFIG) with
# components) with its version file, and pkg-config files (meshcast,
# meshcast-host, meshcast-reader, meshcast-c).
include(CMakePackageConfigHelpers)

# One export set a component, so a user's find_package looks only for what
# the components asked for need: core (meshcast::meshcast, always), host
# (meshcast::host, with its Vulkan backend meshcast::vulkan when built) and
# reader (meshcast::reader, Assimp).
install(TARGETS meshcast_core EXPORT meshcastCoreTargets ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
set(MESHCAST_HOST_INSTALLED meshcast_host)
if(MESHCAST_VULKAN)
  list(APPEND MESHCAST_HOST_INSTALLED meshcast_gpu)  # the host layer's static part, linked through meshcast::host
endif()
install(TARGETS ${MESHCAST_HOST_INSTALLED} EXPORT meshcastHostTargets ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
if(MESHCAST_READER)
  install(TARGETS meshcast_io EXPORT meshcastReaderTargets ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
endif()
install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/meshcast DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
if(MESHCAST_TOOLS)
  install(TARGETS meshcast RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()

if(MESHCAST_C_API)
  install(TARGETS meshcast_c meshcast_c_static EXPORT meshcastCTargets LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
          ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
endif()

set(MESHCAST_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/meshcast)
if(MESHCAST_C_API)
  install(EXPORT meshcastCTargets NAMESPACE meshcast:: DESTINATION ${MESHCAST_CMAKE_DIR})
endif()
install(EXPORT meshcastCoreTargets NAMESPACE meshcast:: DESTINATION ${MESHCAST_CMAKE_DIR})
install(EXPORT meshcastHostTargets NAMESPACE meshcast:: DESTINATION ${MESHCAST_CMAKE_DIR})
if(MESHCAST_READER)
  install(EXPORT meshcastReaderTargets NAMESPACE meshcast:: DESTINATION ${MESHCAST_CMAKE_DIR})
endif()
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/meshcastConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/meshcastConfig.cmake INSTALL_DESTINATION ${MESHCAST_CMAKE_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/meshcastConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/meshcastConfig.cmake ${PROJECT_BINARY_DIR}/meshcastConfigVersion.cmake
        DESTINATION ${MESHCAST_CMAKE_DIR})

# pkg-config: the libraries in link order, with what they need of the system.
set(MESHCAST_HOST_LIBS "-lmeshcast_host")
if(MESHCAST_VULKAN)
  string(APPEND MESHCAST_HOST_LIBS " -lmeshcast_vulkan -ldl")
endif()
# The prefix found from the .pc file's own folder, so the package may be
# installed anywhere (cmake --install --prefix) and still point at itself.
file(RELATIVE_PATH MESHCAST_PC_TO_PREFIX /${CMAKE_INSTALL_LIBDIR}/pkgconfig /)
string(REGEX REPLACE "/$" "" MESHCAST_PC_TO_PREFIX "${MESHCAST_PC_TO_PREFIX}")
set(MESHCAST_PC_FILES meshcast meshcast-host)
if(MESHCAST_READER)
  list(APPEND MESHCAST_PC_FILES meshcast-reader)
endif()
if(MESHCAST_C_API)
  list(APPEND MESHCAST_PC_FILES meshcast-c)
endif()
foreach(pc ${MESHCAST_PC_FILES})
  configure_file(${PROJECT_SOURCE_DIR}/cmake/${pc}.pc.in ${PROJECT_BINARY_DIR}/${pc}.pc @ONLY)
  install(FILES ${PROJECT_BINARY_DIR}/${pc}.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
endforeach()
