# The check of a scene's PARAMS against the simulator's options table (options.hpp): the
# checker clothsim_params is compiled at configure time (it needs only options.cpp) and set
# as blender2ogl_add_scene()'s BLENDER2OGL_PARAMS_CHECK, so that a key or value the simulator
# would refuse stops the configure, with the simulator's own words. The converter's package
# knows no keys; the simulator's package installs the checker and sets the same property.
include_guard(GLOBAL)

function(clothsim_params_checker core_dir)
  set(sources "${core_dir}/src/options.cpp" "${core_dir}/tools/clothsim_params.cpp")
  set(exe "${CMAKE_BINARY_DIR}/clothsim-params-check/clothsim_params${CMAKE_EXECUTABLE_SUFFIX}")
  # Built again only when a source or the table changes (and then the configure re-runs).
  set(stamp "")
  foreach(f IN LISTS sources ITEMS "${core_dir}/include/clothsim/options.hpp")
    file(SHA256 "${f}" h)
    string(APPEND stamp "${h}")
    set_property(DIRECTORY "${CMAKE_SOURCE_DIR}" APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS "${f}")
  endforeach()
  string(APPEND stamp "${CMAKE_CXX_COMPILER}${CMAKE_CXX_FLAGS}")
  if(NOT EXISTS "${exe}" OR NOT CLOTHSIM_PARAMS_CHECK_STAMP STREQUAL stamp)
    try_compile(ok "${CMAKE_BINARY_DIR}/clothsim-params-check/build"
      SOURCES ${sources}
      CMAKE_FLAGS "-DINCLUDE_DIRECTORIES=${core_dir}/include"
      CXX_STANDARD 20 CXX_STANDARD_REQUIRED ON CXX_EXTENSIONS OFF
      OUTPUT_VARIABLE log
      COPY_FILE "${exe}")
    if(NOT ok)
      message(FATAL_ERROR "clothsim: could not compile the PARAMS checker (${core_dir}/tools/clothsim_params.cpp):\n${log}")
    endif()
    set(CLOTHSIM_PARAMS_CHECK_STAMP "${stamp}" CACHE INTERNAL "sources of the PARAMS checker")
  endif()
  set_property(GLOBAL PROPERTY BLENDER2OGL_PARAMS_CHECK "${exe}")
endfunction()
