# Installs the engine libraries, headers and a CMake package so that an embedding project can
#   find_package(sdfkit REQUIRED)
#   target_link_libraries(tool PRIVATE sdfkit::sdfkit)
# Every installed target is exported with its usage requirements: include directories as
# $<INSTALL_INTERFACE:include>, build-tree-only ones (sdfkit_compile_options) as BUILD_INTERFACE,
# and private dependencies of these static libraries as link-only imports that sdfkitConfig.cmake
# finds again (find_dependency). The shaders and kernels are compiled into sdfkit_vulkan and
# sdfkit_opencl, so nothing else is needed at run time.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

# The public headers use C++20 (std::span, defaulted operator==): say so to consumers.
target_compile_features(sdfkit_core PUBLIC cxx_std_20)

set(_sdfkit_export_targets sdfkit_core sdfkit_io sdfkit_post sdfkit)
foreach(_t sdfkit_opencl sdfkit_vulkan sdfkit_render sdfkit_diffuse sdfkit_passes sdfkit_skeleton sdfkit_pointcloud sdfkit_diffusion sdfkit_vulkan_shaders sdfkit_opencl_kernels)
  if(TARGET ${_t})
    get_target_property(_type ${_t} TYPE)
    if(NOT _type STREQUAL "UTILITY")
      list(APPEND _sdfkit_export_targets ${_t})
    endif()
  endif()
endforeach()

# Installed names match the build tree's aliases: sdfkit_core is sdfkit::core in both.
foreach(_t IN LISTS _sdfkit_export_targets)
  string(REGEX REPLACE "^sdfkit_" "" _short "${_t}")
  if(NOT _short STREQUAL _t AND TARGET sdfkit::${_short})
    set_target_properties(${_t} PROPERTIES EXPORT_NAME ${_short})
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
