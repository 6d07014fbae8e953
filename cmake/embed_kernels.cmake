# Writes OUT, a C++ file holding every file of FILES as a string, looked up by file name through the
# function FUNCTION declared in HEADER (defaults: the OpenCL kernels, sim/embedded_kernels.h).
if(NOT FUNCTION)
  set(FUNCTION embedded_kernel_files)
endif()
if(NOT HEADER)
  set(HEADER sim/embedded_kernels.h)
endif()
set(body "#include \"${HEADER}\"\n\nnamespace thaw {\n\nconst std::map<std::string, std::string_view>& ${FUNCTION}() {\n  static const std::map<std::string, std::string_view> files = {\n")
string(REPLACE "|" ";" FILES "${FILES}")
foreach(f ${FILES})
  get_filename_component(name ${f} NAME)
  file(READ ${f} text)
  # Raw string literal; the delimiter cannot appear in OpenCL C or GLSL.
  string(APPEND body "    {\"${name}\", R\"thaw_cl(${text})thaw_cl\"},\n")
endforeach()
string(APPEND body "  };\n  return files;\n}\n\n}  // namespace thaw\n")
file(WRITE ${OUT}.tmp "${body}")
file(COPY_FILE ${OUT}.tmp ${OUT} ONLY_IF_DIFFERENT)
