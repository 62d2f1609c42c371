# Installs the engine libraries, headers and a CMake package so that an embedding project can
#   find_package(sdfkit REQUIRED)
#   target_link_libraries(tool PRIVATE sdfkit::sdfkit)
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(_sdfkit_export_targets sdfkit_core sdfkit_io sdfkit_post sdfkit)
foreach(_t sdfkit_opencl sdfkit_vulkan sdfkit_render sdfkit_passes sdfkit_skeleton sdfkit_vulkan_shaders sdfkit_opencl_kernels)
  if(TARGET ${_t})
    get_target_property(_type ${_t} TYPE)
    if(NOT _type STREQUAL "UTILITY")
      list(APPEND _sdfkit_export_targets ${_t})
    endif()
  endif()
endforeach()

install(TARGETS ${_sdfkit_export_targets}
  EXPORT sdfkitTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/engine/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(EXPORT sdfkitTargets NAMESPACE sdfkit:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/sdfkit)

set(SDFKIT_PACKAGE_WITH_OPENCL ${SDFKIT_WITH_OPENCL})
set(SDFKIT_PACKAGE_WITH_VULKAN ${SDFKIT_WITH_VULKAN})
set(SDFKIT_PACKAGE_WITH_SKELETON OFF)
if(TARGET sdfkit_skeleton)
  set(SDFKIT_PACKAGE_WITH_SKELETON ON)
endif()
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/sdfkitConfig.cmake.in
  ${PROJECT_BINARY_DIR}/sdfkitConfig.cmake
  INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/sdfkit)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/sdfkitConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/sdfkitConfig.cmake ${PROJECT_BINARY_DIR}/sdfkitConfigVersion.cmake
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/sdfkit)
