# Writes OUTPUT: a C++ file holding every .cl file of INPUTS ('|'-separated) as a raw string literal,
# looked up by family name (the file name without .cl). A line `#include "NAME.h"` of a .cl file is
# replaced by the text of NAME.h beside it (a header shared with the host code), followed by a #line
# directive that keeps the build log's line numbers those of the .cl file.
cmake_minimum_required(VERSION 3.20)
string(REPLACE "|" ";" INPUTS "${INPUTS}")

# The text of `file` with its includes put in place, into `out`.
function(kernel_text file out)
  get_filename_component(dir ${file} DIRECTORY)
  file(READ ${file} rest)
  set(text "")
  set(line 1)  # the line number of the first line of `rest` in `file`
  set(pattern "(^|\n)#include \"([A-Za-z0-9_]+\\.h)\"\n")
  string(REGEX MATCH "${pattern}" directive "${rest}")
  while(directive)
    set(header ${CMAKE_MATCH_2})
    string(FIND "${rest}" "${directive}" at)
    string(LENGTH "${directive}" length)
    if(directive MATCHES "^\n")  # the newline ending the line before belongs to that line
      math(EXPR at "${at} + 1")
      math(EXPR length "${length} - 1")
    endif()
    string(SUBSTRING "${rest}" 0 ${at} before)
    math(EXPR after "${at} + ${length}")
    string(SUBSTRING "${rest}" ${after} -1 rest)
    string(REGEX MATCHALL "\n" newlines "${before}")
    list(LENGTH newlines lines_before)
    math(EXPR line "${line} + ${lines_before} + 1")
    file(READ ${dir}/${header} header_text)
    string(APPEND text "${before}${header_text}#line ${line}\n")
    string(REGEX MATCH "${pattern}" directive "${rest}")
  endwhile()
  set(${out} "${text}${rest}" PARENT_SCOPE)
endfunction()

set(body "// Generated from kernels/*.cl by cmake/embed_kernels.cmake. Do not edit.\n#include \"device/kernel_sources.hpp\"\n\nnamespace clfractal::detail {\n\nconst KernelSource kernel_sources[] = {\n")
foreach(f ${INPUTS})
  get_filename_component(family ${f} NAME_WE)
  kernel_text(${f} text)
  string(APPEND body "    {\"${family}\", R\"CLFRACTAL_KERNEL(${text})CLFRACTAL_KERNEL\"},\n")
endforeach()
string(APPEND body "    {nullptr, nullptr}};\n\n}  // namespace clfractal::detail\n")
file(WRITE ${OUTPUT}.tmp "${body}")
file(COPY_FILE ${OUTPUT}.tmp ${OUTPUT} ONLY_IF_DIFFERENT)
file(REMOVE ${OUTPUT}.tmp)
