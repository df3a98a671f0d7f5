# Turns GLSL files into C++ string constants at build time, so the viewer never
# has to find shader files next to an installed or moved binary.
# Usage: cmake -DOUT=file.cpp -DINPUTS="a.vert;b.frag" -P embed.cmake
set(body "// Generated from shaders/ by shaders/embed.cmake; edit the GLSL files instead.\n")
string(APPEND body "#include \"shaders/shaders.h\"\n\nnamespace pdflab::shaders {\n\n")
foreach(input IN LISTS INPUTS)
  file(READ "${input}" text)
  get_filename_component(name "${input}" NAME)
  string(MAKE_C_IDENTIFIER "${name}" ident)
  string(APPEND body "const char* const ${ident} = R\"pdflab_glsl(${text})pdflab_glsl\";\n\n")
endforeach()
string(APPEND body "}  // namespace pdflab::shaders\n")
file(WRITE "${OUT}.tmp" "${body}")
file(COPY_FILE "${OUT}.tmp" "${OUT}" ONLY_IF_DIFFERENT)
file(REMOVE "${OUT}.tmp")
