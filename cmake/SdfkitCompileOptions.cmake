# Warning and sanitizer flags shared by every sdfkit target.
# Use: sdfkit_target_defaults(<target>) after add_library/add_executable.

add_library(sdfkit_compile_options INTERFACE)
target_compile_options(sdfkit_compile_options INTERFACE
  -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor -Wcast-align -Woverloaded-virtual
  -Wimplicit-fallthrough)
if(SDFKIT_WERROR)
  target_compile_options(sdfkit_compile_options INTERFACE -Werror)
endif()
if(SDFKIT_SANITIZE)
  target_compile_options(sdfkit_compile_options INTERFACE
    -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  target_link_options(sdfkit_compile_options INTERFACE -fsanitize=address,undefined)
endif()

if(SDFKIT_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "SDFKIT_FUZZ needs clang (libFuzzer): use the `fuzz` preset")
  endif()
  # Coverage for libFuzzer on every sdfkit target; the harnesses link the fuzzer's main.
  target_compile_options(sdfkit_compile_options INTERFACE
    -fsanitize=fuzzer-no-link,address,undefined -fno-omit-frame-pointer
    -fno-sanitize-recover=undefined)
  target_link_options(sdfkit_compile_options INTERFACE -fsanitize=address,undefined)
endif()

function(sdfkit_target_defaults target)
  target_link_libraries(${target} PRIVATE $<BUILD_INTERFACE:sdfkit_compile_options>)
endfunction()
