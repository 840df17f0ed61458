# ddemap_precompile(TARGET [HEADER ...]): TARGET's files compile with the precompiled header
# cmake/pch.hpp (the standard and Eigen headers, and the declarations of the dense
# decompositions compiled once) and the extra HEADERs (e.g. <CLI/CLI.hpp> for the program).
# ddemap_precompile_reuse(TARGET FROM): TARGET uses the precompiled header of FROM (same flags).
# DDEMAP_PCH=OFF turns it off (the build is then slower, the result the same).
option(DDEMAP_PCH "Precompiled headers (faster builds)" ON)
function(ddemap_precompile target)
  if(NOT DDEMAP_PCH)
    return()
  endif()
  target_precompile_headers(${target} PRIVATE "$<$<COMPILE_LANGUAGE:CXX>:${PROJECT_SOURCE_DIR}/cmake/pch.hpp>" ${ARGN})
endfunction()
function(ddemap_precompile_reuse target from)
  if(DDEMAP_PCH)
    target_precompile_headers(${target} REUSE_FROM ${from})
  endif()
endfunction()
