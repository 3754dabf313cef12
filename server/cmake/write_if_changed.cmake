# write_if_changed.cmake — write_if_changed(PATH TEXT): writes TEXT to PATH
# only when it differs from what PATH holds, so that a regenerated header
# does not rebuild its dependants for nothing. Included by the embed_*.cmake scripts.
function(write_if_changed path text)
  set(old "")
  if(EXISTS "${path}")
    file(READ "${path}" old)
  endif()
  if(NOT old STREQUAL text)
    file(WRITE "${path}" "${text}")
  endif()
endfunction()
