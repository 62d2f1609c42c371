# sdfkit-vulkan-bench: the depth-peeling backend's benchmark. The timing logic (vulkan_bench.hpp/
# .cpp) is a small library the shared sdfkit-bench can link; vulkan_bench_main.cpp is its CLI.
# Include this file from apps/CMakeLists.txt (or, until the lead does, engine/vulkan includes it).
add_library(sdfkit_vulkan_bench STATIC ${CMAKE_CURRENT_LIST_DIR}/vulkan_bench.cpp)
target_include_directories(sdfkit_vulkan_bench PUBLIC ${CMAKE_CURRENT_LIST_DIR})
target_link_libraries(sdfkit_vulkan_bench PUBLIC sdfkit::vulkan)
sdfkit_target_defaults(sdfkit_vulkan_bench)

add_executable(sdfkit-vulkan-bench ${CMAKE_CURRENT_LIST_DIR}/vulkan_bench_main.cpp)
target_link_libraries(sdfkit-vulkan-bench PRIVATE sdfkit_vulkan_bench sdfkit::io
  $<TARGET_NAME_IF_EXISTS:sdfkit::reference>)
target_compile_definitions(sdfkit-vulkan-bench PRIVATE
  $<$<TARGET_EXISTS:sdfkit::reference>:SDFKIT_BENCH_HAS_REFERENCE>)
sdfkit_target_defaults(sdfkit-vulkan-bench)
