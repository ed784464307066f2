# Sanitizer and fuzzing builds (docs/reliability.md).
#   -DCLFRACTAL_SANITIZE=address,undefined   (or thread): every target instrumented; UBSan
#                                             reports are fatal, so a test that hits one fails.
#   -DCLFRACTAL_FUZZ=ON (with clang):         the libFuzzer targets in fuzz/, the library
#                                             instrumented for coverage with ASan+UBSan.
set(CLFRACTAL_SANITIZE "" CACHE STRING "Sanitizers for every target, e.g. address,undefined or thread")
option(CLFRACTAL_FUZZ "Build the libFuzzer targets in fuzz/ (needs clang with -fsanitize=fuzzer)" OFF)
if(CLFRACTAL_SANITIZE)
  add_compile_options(-fsanitize=${CLFRACTAL_SANITIZE} -fno-omit-frame-pointer -fno-sanitize-recover=all)
  add_link_options(-fsanitize=${CLFRACTAL_SANITIZE})
endif()
if(CLFRACTAL_FUZZ)
  include(CheckCXXSourceCompiles)
  set(CMAKE_REQUIRED_LINK_OPTIONS -fsanitize=fuzzer)
  check_cxx_source_compiles([[
    #include <cstdint>
    #include <cstddef>
    extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t*, std::size_t) { return 0; }]] CLFRACTAL_HAS_LIBFUZZER)
  unset(CMAKE_REQUIRED_LINK_OPTIONS)
  if(NOT CLFRACTAL_HAS_LIBFUZZER)
    message(FATAL_ERROR "CLFRACTAL_FUZZ needs clang with libFuzzer (Debian: clang-14 libfuzzer-14-dev; "
                        "configure with CC=clang-14 CXX=clang++-14)")
  endif()
  add_compile_options(-fsanitize=fuzzer-no-link,address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all)
  add_link_options(-fsanitize=address,undefined)
endif()
