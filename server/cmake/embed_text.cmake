# embed_text.cmake — turns one text file (INPUT) into a C++ header (OUTPUT)
# holding it as a raw string literal named NAME in namespace hmpm::server::generated,
# so the server never reads it from disk at run time (the job schema of
# GET /processes/hmpm).
# Usage: cmake -DINPUT=file -DOUTPUT=file.hpp -DNAME=identifier -P embed_text.cmake
include(${CMAKE_CURRENT_LIST_DIR}/write_if_changed.cmake)
file(READ "${INPUT}" content)
if(content MATCHES "\\)hmpm_text\"")
  message(FATAL_ERROR "${INPUT} contains the raw-string delimiter")
endif()
set(text "// Generated from ${INPUT} by server/cmake/embed_text.cmake; do not edit.\n")
string(APPEND text "#pragma once\n\nnamespace hmpm::server::generated {\n\n")
string(APPEND text "inline constexpr const char ${NAME}[] = R\"hmpm_text(${content})hmpm_text\";\n")
string(APPEND text "\n}  // namespace hmpm::server::generated\n")
write_if_changed("${OUTPUT}" "${text}")
