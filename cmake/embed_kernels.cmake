# Writes OUT, a C++ file holding every file of FILES as a string, looked up by file name.
set(body "#include \"sim/embedded_kernels.h\"\n\nnamespace thaw {\n\nconst std::map<std::string, std::string_view>& embedded_kernel_files() {\n  static const std::map<std::string, std::string_view> files = {\n")
string(REPLACE "|" ";" FILES "${FILES}")
foreach(f ${FILES})
  get_filename_component(name ${f} NAME)
  file(READ ${f} text)
  # Raw string literal; the delimiter cannot appear in OpenCL C.
  string(APPEND body "    {\"${name}\", R\"thaw_cl(${text})thaw_cl\"},\n")
endforeach()
string(APPEND body "  };\n  return files;\n}\n\n}  // namespace thaw\n")
file(WRITE ${OUT}.tmp "${body}")
file(COPY_FILE ${OUT}.tmp ${OUT} ONLY_IF_DIFFERENT)
