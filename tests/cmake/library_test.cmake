# Driven by ctest (-DMODE=install|snippet): `cmake --install` gives a tree from which an outside
# project builds the README's "Use it as a library" example exactly as written there (its
# CMakeLists.txt and main.cpp are read from the README), with a scene of its own, and runs it.
cmake_minimum_required(VERSION 3.25)
foreach(v MODE BUILD_DIR WORK README MODEL)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "library_test.cmake: -D${v}= missing")
  endif()
endforeach()
set(prefix "${WORK}/prefix")

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  set(last_output "${out}${err}" PARENT_SCOPE)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}\n${out}${err}")
  endif()
endfunction()

if(MODE STREQUAL "install")
  file(REMOVE_RECURSE "${prefix}")
  run(${CMAKE_COMMAND} --install "${BUILD_DIR}" --prefix "${prefix}")
  foreach(f include/clothsim/sim.hpp include/clothsim/step.hpp include/clothsim/scene.hpp
            include/clothsim/collision.hpp include/clothsim/options.hpp lib/libclothsim_core.a
            lib/cmake/clothsim/clothsimConfig.cmake bin/clothsim_params bin/blender2ogl)
    if(NOT EXISTS "${prefix}/${f}")
      message(FATAL_ERROR "not installed: ${f}")
    endif()
  endforeach()
  return()
endif()

# The README's section, and its first cmake and cpp code blocks.
file(READ "${README}" text)
string(FIND "${text}" "## Use it as a library" at)
if(at LESS 0)
  message(FATAL_ERROR "${README} has no section '## Use it as a library'")
endif()
string(SUBSTRING "${text}" ${at} -1 text)
foreach(lang cmake cpp)
  string(FIND "${text}" "```${lang}\n" begin)
  if(begin LESS 0)
    message(FATAL_ERROR "the README's library section has no ```${lang} block")
  endif()
  string(LENGTH "```${lang}\n" skip)
  math(EXPR begin "${begin} + ${skip}")
  string(SUBSTRING "${text}" ${begin} -1 rest)
  string(FIND "${rest}" "```" end)
  string(SUBSTRING "${rest}" 0 ${end} block_${lang})
endforeach()
string(REGEX MATCHALL "\n" main_lines "${block_cpp}")
list(LENGTH main_lines main_lines)
if(main_lines GREATER 25)
  message(FATAL_ERROR "the README's main.cpp has ${main_lines} lines (at most 25)")
endif()

set(src "${WORK}/snippet/src")
set(bin "${WORK}/snippet/build")
file(REMOVE_RECURSE "${WORK}/snippet")
file(WRITE "${src}/CMakeLists.txt" "${block_cmake}")
file(WRITE "${src}/main.cpp" "${block_cpp}")
file(COPY "${MODEL}" DESTINATION "${src}")
run(${CMAKE_COMMAND} -S "${src}" -B "${bin}" -G Ninja -DCMAKE_BUILD_TYPE=Release "-DCMAKE_PREFIX_PATH=${prefix}"
    "-DCMAKE_CXX_COMPILER=${CXX_COMPILER}" "-DCMAKE_CXX_FLAGS=${CXX_FLAGS} -Wall -Wextra -Werror"
    "-DCMAKE_EXE_LINKER_FLAGS=${LINKER_FLAGS}")
run(${CMAKE_COMMAND} --build "${bin}")
run("${bin}/curtain")
# 49 masses, two of them pinned at y = 2: after 2 s it hangs, its lowest row between 0.6 and
# 0.9 m (it stretches under its weight), still swinging a little.
if(NOT last_output MATCHES "^curtain: 49 masses, t = 2.00 s, lowest y 0\\.[6-8][0-9][0-9] m, kinetic energy [0-9.e+-]+ J\n$")
  message(FATAL_ERROR "unexpected output of the README's example:\n${last_output}")
endif()
