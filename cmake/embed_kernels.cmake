# Writes OUTPUT: a C++ file holding every .cl file of INPUTS ('|'-separated) as a raw string literal,
# looked up by family name (the file name without .cl).
string(REPLACE "|" ";" INPUTS "${INPUTS}")
set(body "// Generated from kernels/*.cl by cmake/embed_kernels.cmake. Do not edit.\n#include \"device/kernel_sources.hpp\"\n\nnamespace clfractal::detail {\n\nconst KernelSource kernel_sources[] = {\n")
foreach(f ${INPUTS})
  get_filename_component(family ${f} NAME_WE)
  file(READ ${f} text)
  string(APPEND body "    {\"${family}\", R\"CLFRACTAL_KERNEL(${text})CLFRACTAL_KERNEL\"},\n")
endforeach()
string(APPEND body "    {nullptr, nullptr}};\n\n}  // namespace clfractal::detail\n")
file(WRITE ${OUTPUT}.tmp "${body}")
file(COPY_FILE ${OUTPUT}.tmp ${OUTPUT} ONLY_IF_DIFFERENT)
file(REMOVE ${OUTPUT}.tmp)
