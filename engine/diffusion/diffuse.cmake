# sdfkit_diffuse: texture-space diffusion through an atlas mapping (issue 13): the host side
# (diffuse.cpp; diffuse_mesh.cpp: skeleton -> build_stm -> diffusion) and its render-graph passes (passes/atlas_*.cpp, shaders glsl/atlas_*, embedded
# in sdfkit_vulkan with the others). Included from engine/CMakeLists.txt when Vulkan is on.
add_library(sdfkit_diffuse
  ${CMAKE_CURRENT_LIST_DIR}/diffuse.cpp
  ${CMAKE_CURRENT_LIST_DIR}/diffuse_mesh.cpp
  ${PROJECT_SOURCE_DIR}/passes/atlas_raster.cpp
  ${PROJECT_SOURCE_DIR}/passes/atlas_blur.cpp
  ${PROJECT_SOURCE_DIR}/passes/atlas_sample.cpp
  ${PROJECT_SOURCE_DIR}/passes/atlas_dilate.cpp)
add_library(sdfkit::diffuse ALIAS sdfkit_diffuse)
target_include_directories(sdfkit_diffuse PRIVATE $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/passes>)
target_link_libraries(sdfkit_diffuse PUBLIC sdfkit::core sdfkit::vulkan sdfkit::diffusion sdfkit::skeleton PRIVATE sdfkit::post)
sdfkit_target_defaults(sdfkit_diffuse)
target_compile_options(sdfkit_diffuse PRIVATE -Wno-missing-field-initializers)
