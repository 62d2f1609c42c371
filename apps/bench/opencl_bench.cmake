# sdfkit-opencl-bench: the OpenCL backend against the Embree reference (see opencl_bench.cpp).
# Included from apps/; to be folded into sdfkit-bench.
if(SDFKIT_WITH_OPENCL AND SDFKIT_BUILD_BENCH)
  find_package(CLI11 REQUIRED)
  add_executable(sdfkit_opencl_bench ${CMAKE_CURRENT_LIST_DIR}/opencl_bench.cpp)
  set_target_properties(sdfkit_opencl_bench PROPERTIES OUTPUT_NAME sdfkit-opencl-bench)
  target_link_libraries(sdfkit_opencl_bench PRIVATE sdfkit::opencl sdfkit::io CLI11::CLI11)
  if(TARGET sdfkit::reference)
    target_link_libraries(sdfkit_opencl_bench PRIVATE sdfkit::reference)
    target_compile_definitions(sdfkit_opencl_bench PRIVATE SDFKIT_BENCH_HAS_EMBREE=1)
  endif()
  sdfkit_target_defaults(sdfkit_opencl_bench)
endif()
