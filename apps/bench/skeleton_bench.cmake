# sdfkit_skeleton_bench: SDF-driven skeletons against CGAL's Mean_curvature_flow_skeletonization
# on CGAL's data meshes. CGAL is GPL: only this benchmark uses its headers, never the library.
# Included from apps/bench/CMakeLists.txt.
if(NOT SDFKIT_WITH_REFERENCE)
  return()
endif()
find_package(CGAL QUIET)
find_package(Eigen3 3.3 QUIET NO_MODULE)
if(NOT CGAL_FOUND OR NOT TARGET Eigen3::Eigen)
  message(STATUS "skeleton benchmark skipped: CGAL (libcgal-dev) or Eigen3 not found")
  return()
endif()

set(SDFKIT_SKELETON_BENCH_DATA "${CMAKE_CURRENT_BINARY_DIR}/skeleton_bench_data")
set(_skeleton_bench_meshes elephant.off refined_elephant.off camel.off hand.off)
set(_members)
foreach(m IN LISTS _skeleton_bench_meshes)
  list(APPEND _members "data/meshes/${m}")
endforeach()
file(MAKE_DIRECTORY "${SDFKIT_SKELETON_BENCH_DATA}")
execute_process(
  COMMAND tar -xzf "/usr/share/doc/libcgal-dev/data.tar.gz" -C "${SDFKIT_SKELETON_BENCH_DATA}"
          --strip-components=2 ${_members}
  RESULT_VARIABLE _skeleton_bench_tar)
if(NOT _skeleton_bench_tar EQUAL 0)
  message(STATUS "skeleton benchmark skipped: CGAL's data.tar.gz (libcgal-demo) is missing")
  return()
endif()

# The evaluation's data set: all of CGAL's data/ (sdfkit_skeleton_bench --eval DIR).
set(SDFKIT_SKELETON_EVAL_DATA "${CMAKE_CURRENT_BINARY_DIR}/skeleton_eval_data")
if(NOT EXISTS "${SDFKIT_SKELETON_EVAL_DATA}/meshes")
  file(MAKE_DIRECTORY "${SDFKIT_SKELETON_EVAL_DATA}")
  execute_process(
    COMMAND tar -xzf "/usr/share/doc/libcgal-dev/data.tar.gz" -C "${SDFKIT_SKELETON_EVAL_DATA}" --strip-components=1
    RESULT_VARIABLE _skeleton_eval_tar)
endif()

add_executable(sdfkit_skeleton_bench ${CMAKE_CURRENT_LIST_DIR}/skeleton_bench.cpp
  ${CMAKE_CURRENT_LIST_DIR}/skeleton_eval.cpp)
# The evaluation's containment checks use the library's CPU BVH (a private header).
target_include_directories(sdfkit_skeleton_bench PRIVATE ${PROJECT_SOURCE_DIR}/engine/skeleton)
target_link_libraries(sdfkit_skeleton_bench PRIVATE
  sdfkit::skeleton sdfkit::reference sdfkit::io CGAL::CGAL Eigen3::Eigen)
target_compile_definitions(sdfkit_skeleton_bench PRIVATE
  CGAL_EIGEN3_ENABLED SDFKIT_SKELETON_BENCH_DATA="${SDFKIT_SKELETON_BENCH_DATA}")
# The engine's own ray caster (OpenCL; PoCL on a CPU) is the default SDF backend when built.
if(TARGET sdfkit_opencl)
  target_link_libraries(sdfkit_skeleton_bench PRIVATE sdfkit::opencl)
  target_compile_definitions(sdfkit_skeleton_bench PRIVATE SDFKIT_SKELETON_BENCH_OPENCL=1)
endif()
sdfkit_target_defaults(sdfkit_skeleton_bench)
