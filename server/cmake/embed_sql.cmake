# embed_sql.cmake — turns the migration files NNNN_name.sql of SQL_DIR into a
# C++ header (OUTPUT) holding them as raw string literals, in file-name order,
# so the server never reads a migration from disk at run time.
# Usage: cmake -DSQL_DIR=dir -DOUTPUT=file.hpp [-DNAMESPACE=sqlite] -P embed_sql.cmake
# NAMESPACE is the store's namespace under hmpm::server (one header per store).
include(${CMAKE_CURRENT_LIST_DIR}/write_if_changed.cmake)
if(NOT NAMESPACE)
  set(NAMESPACE sqlite)
endif()
file(GLOB files "${SQL_DIR}/*.sql")
list(SORT files)
set(text "// Generated from ${SQL_DIR} by server/cmake/embed_sql.cmake; do not edit.\n")
string(APPEND text "#pragma once\n\nnamespace hmpm::server::${NAMESPACE} {\n\n")
string(APPEND text "struct Migration {\n  int version;\n  const char* name;\n  const char* sql;\n};\n\n")
string(APPEND text "inline constexpr Migration migrations[] = {\n")
foreach(file IN LISTS files)
  get_filename_component(name "${file}" NAME_WE)
  if(NOT name MATCHES "^([0-9]+)_")
    message(FATAL_ERROR "migration ${file}: the name must start with its version, e.g. 0003_x.sql")
  endif()
  math(EXPR version "${CMAKE_MATCH_1}")
  file(READ "${file}" sql)
  if(sql MATCHES "\\)hmpm_sql\"")
    message(FATAL_ERROR "migration ${file} contains the raw-string delimiter")
  endif()
  string(APPEND text "    {${version}, \"${name}\", R\"hmpm_sql(${sql})hmpm_sql\"},\n")
endforeach()
string(APPEND text "};\n\n}  // namespace hmpm::server::${NAMESPACE}\n")
write_if_changed("${OUTPUT}" "${text}")
