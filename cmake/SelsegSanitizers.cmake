# Sanitizer and fuzzing builds (docs/reliability.md). Included from the top-level
# CMakeLists.txt before any target is defined, so the flags reach every target.
#
#   SELSEG_SANITIZE=ON  AddressSanitizer + UndefinedBehaviorSanitizer on everything
#                       (library, tools, tests); any finding aborts the process.
#   SELSEG_FUZZ=ON      also builds the libFuzzer targets in test/fuzz (clang only);
#                       implies SELSEG_SANITIZE and adds coverage instrumentation.

option(SELSEG_SANITIZE "Build everything with AddressSanitizer and UndefinedBehaviorSanitizer" OFF)
option(SELSEG_FUZZ "Build the libFuzzer targets in test/fuzz (needs clang)" OFF)

if(SELSEG_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
    message(FATAL_ERROR "SELSEG_FUZZ needs clang (libFuzzer): configure with "
      "-DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ "
      "(Debian: apt-get install clang libclang-rt-dev libomp-dev)")
  endif()
  set(SELSEG_SANITIZE ON CACHE BOOL "" FORCE)
endif()

if(SELSEG_SANITIZE)
  set(SELSEG_SANITIZER_FLAGS
    -fsanitize=address,undefined
    -fno-sanitize-recover=all   # a UBSan finding is an error, not a warning
    -fno-omit-frame-pointer
    -g)
  if(SELSEG_FUZZ)
    list(APPEND SELSEG_SANITIZER_FLAGS -fsanitize=fuzzer-no-link)
  endif()
  add_compile_options(${SELSEG_SANITIZER_FLAGS})
  add_link_options(-fsanitize=address,undefined)
  message(STATUS "Sanitizers: ${SELSEG_SANITIZER_FLAGS}")
endif()

# With clang the sanitizer runtime is linked into executables only, so a shared library
# built with the sanitizers has undefined __asan_* symbols until it is loaded: drop
# --no-undefined from such a library's link options.
function(selseg_sanitizer_allow_runtime_symbols target)
  if(NOT SELSEG_SANITIZE)
    return()
  endif()
  get_target_property(options ${target} LINK_OPTIONS)
  if(options)
    list(REMOVE_ITEM options "LINKER:--no-undefined")
    set_target_properties(${target} PROPERTIES LINK_OPTIONS "${options}")
  endif()
endfunction()
