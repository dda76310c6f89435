# Driven by ctest (blender2ogl.params_keys): blender2ogl_add_scene() refuses PARAMS keys the
# simulator does not read, at configure time, naming the scene and the key, with a hint for
# the command line's hyphenated spelling. Each case runs the function in a child cmake -P.
cmake_minimum_required(VERSION 3.25)
if(NOT DEFINED MODULE OR NOT DEFINED WORK)
  message(FATAL_ERROR "params_test.cmake: -DMODULE= and -DWORK= needed")
endif()
file(MAKE_DIRECTORY "${WORK}")

function(expect params want)
  file(WRITE "${WORK}/case.cmake"
       "include(\"${MODULE}\")\nblender2ogl_add_scene(flag OBJ \"${WORK}/absent.obj\" PARAMS ${params})\n")
  execute_process(COMMAND ${CMAKE_COMMAND} -P "${WORK}/case.cmake" RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  string(REGEX REPLACE "[ \t\r\n]+" " " text "${out}${err}")  # (CMake wraps long messages)
  if(rc EQUAL 0 OR NOT text MATCHES "${want}")
    message(FATAL_ERROR "PARAMS ${params}: expected a failure matching '${want}' (${rc}):\n${out}${err}")
  endif()
endfunction()

# misspelled keys: the scene, each key, a hint, the valid keys
expect("mas=0.01 k-struct=2000" "blender2ogl_add_scene\\(flag\\): bad PARAMS: 'mas' is not a scene parameter \\(did you mean mass\\?\\) 'k-struct' is not a scene parameter \\(did you mean k_struct\\?\\)")
expect("mas=0.01" "Valid keys \\(underscores, as the simulator reads them\\): dt, mass, k_struct, k_bend, damping, gravity_x, gravity_y, gravity_z, epsilon, k_rep")
expect("gravity=-9.81" "'gravity' is not a scene parameter \\(did you mean gravity_x or gravity_y or gravity_z\\?\\)")
expect("K_BEND=1" "'K_BEND' is not a scene parameter \\(did you mean k_bend\\?\\)")
expect("camera=5" "'camera' is not a scene parameter; |'camera' is not a scene parameter Valid")
expect("dt" "'dt': expected KEY=VALUE")
# every valid key passes the check (the configure then stops at the missing model file)
expect("dt=0.001 mass=0.01 k_struct=1 k_bend=1 damping=0.1 gravity_x=0 gravity_y=-9.81 gravity_z=0 epsilon=0.01 k_rep=10"
       "blender2ogl_add_scene\\(flag\\): .*absent.obj: no such model file")
# values the simulator would refuse at every start: not a number, out of range
expect("dt=-1 mass=0" "'dt=-1': dt must be > 0 'mass=0': mass must be > 0")
expect("k_struct=-5 damping=1e-3 k_rep=-0.5" "'k_struct=-5': k_struct must be >= 0 'k_rep=-0.5': k_rep must be >= 0")
expect("dt=abc" "'dt=abc': the value is not a number")
expect("epsilon=0x10" "'epsilon=0x10': the value is not a number")
# a value no double holds, a key given twice (the bake refused them, naming no scene)
expect("k_rep=1e999 mass=2E+0400" "'k_rep=1e999': the value is out of a double's range \\(above 1.8e308\\) 'mass=2E\\+0400': the value is out of a double's range")
expect("k_rep=2e308 mass=1000e306 k_bend=1.7976931348623159e308" "'k_rep=2e308': the value is out of a double's range \\(above 1.8e308\\) 'mass=1000e306': the value is out of a double's range \\(above 1.8e308\\) 'k_bend=1.7976931348623159e308': the value is out")
expect("k_rep=1e-400 gravity_y=1e-320 damping=0.00001e-304" "'k_rep=1e-400': the value is too small for a double \\(below 2.2e-308; write 0\\) 'gravity_y=1e-320': the value is too small .* 'damping=0.00001e-304': the value is too small")
expect("k_rep=0.001e309 k_struct=1.7976931348623157e308 gravity_x=2.2250738585072014e-308 gravity_y=0e-999 k_bend=0.0 damping=000.000e+00999" "blender2ogl_add_scene\\(flag\\): .*absent.obj: no such model file")
expect("dt=0.002 dt=0.001" "'dt=0.001': dt is given twice")
expect("k_rep=1e308 gravity_y=-9.81e-300" "blender2ogl_add_scene\\(flag\\): .*absent.obj: no such model file")
expect("gravity_y=-9.81 dt=2e-3 mass=.5 k_bend=0" "blender2ogl_add_scene\\(flag\\): .*absent.obj: no such model file")
# names the converter would refuse or that would clash: stopped at configure time
function(expect_name name want)
  file(WRITE "${WORK}/case.cmake"
       "include(\"${MODULE}\")\nblender2ogl_add_scene(${name} OBJ \"${WORK}/absent.obj\")\n")
  execute_process(COMMAND ${CMAKE_COMMAND} -P "${WORK}/case.cmake" RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  string(REGEX REPLACE "[ \t\r\n]+" " " text "${out}${err}")
  if(rc EQUAL 0 OR NOT text MATCHES "${want}")
    message(FATAL_ERROR "name ${name}: expected a failure matching '${want}' (${rc}):\n${out}${err}")
  endif()
endfunction()
expect_name("flag_" "the name must be a C\\+\\+ identifier")
expect_name("a__b" "the name must be a C\\+\\+ identifier")
expect_name("2d" "the name must be a C\\+\\+ identifier")
