# Driven by ctest (blender2ogl.params_keys): blender2ogl_add_scene()'s PARAMS at configure
# time. The bake checks KEY=VALUE and repeats itself; with the simulator's checker
# (BLENDER2OGL_PARAMS_CHECK = clothsim_params) an unknown key or a value the simulator would
# refuse stops the configure, naming the scene and the key, with a hint for the command line's
# hyphenated spelling. Each case runs the function in a child cmake -P.
cmake_minimum_required(VERSION 3.25)
if(NOT DEFINED MODULE OR NOT DEFINED WORK OR NOT DEFINED CHECK)
  message(FATAL_ERROR "params_test.cmake: -DMODULE=, -DWORK= and -DCHECK= needed")
endif()
file(MAKE_DIRECTORY "${WORK}")

# Runs `call` (a blender2ogl_add_scene line) in a child cmake with `checker` as
# BLENDER2OGL_PARAMS_CHECK ("" for none); it must fail with a message matching `want`.
function(expect_failure checker call want)
  file(WRITE "${WORK}/case.cmake"
       "set_property(GLOBAL PROPERTY BLENDER2OGL_PARAMS_CHECK \"${checker}\")\ninclude(\"${MODULE}\")\n${call}\n")
  execute_process(COMMAND ${CMAKE_COMMAND} -P "${WORK}/case.cmake" RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  string(REGEX REPLACE "[ \t\r\n]+" " " text "${out}${err}")  # (CMake wraps long messages)
  if(rc EQUAL 0 OR NOT text MATCHES "${want}")
    message(FATAL_ERROR "${call}: expected a failure matching '${want}' (${rc}):\n${out}${err}")
  endif()
endfunction()
function(expect_with checker params want)
  expect_failure("${checker}" "blender2ogl_add_scene(flag OBJ \"${WORK}/absent.obj\" PARAMS ${params})" "${want}")
endfunction()
function(expect params want)
  expect_with("${CHECK}" "${params}" "${want}")
endfunction()
set(passes "blender2ogl_add_scene\\(flag\\): .*absent.obj: no such model file")

# misspelled keys: the scene, each key, a hint, the valid keys
expect("mas=0.01 k-struct=2000" "blender2ogl_add_scene\\(flag\\): bad PARAMS: 'mas=0.01': 'mas' is not a scene parameter \\(did you mean mass\\?\\) 'k-struct=2000': 'k-struct' is not a scene parameter \\(did you mean k_struct\\?\\)")
expect("mas=0.01" "Valid keys \\(underscores, as the simulator reads them\\): dt, material, density, stretch, bend, drag, thickness, strain_limit, air_density, friction, static_friction, mass, k_struct, k_bend, damping, epsilon, k_rep, gravity_x, gravity_y, gravity_z, pin_spin, integrator, self_collision")
expect("gravity=-9.81" "'gravity' is not a scene parameter \\(did you mean gravity_x or gravity_y or gravity_z\\?\\)")
expect("K_BEND=1" "'K_BEND' is not a scene parameter \\(did you mean k_bend\\?\\)")
expect("camera=5" "'camera' is not a scene parameter Valid")
expect("dt" "'dt': expected KEY=VALUE")
# every valid key passes the check (the configure then stops at the missing model file)
expect("dt=0.001 mass=0.01 k_struct=1 k_bend=1 damping=0.1 gravity_x=0 gravity_y=-9.81 gravity_z=0 epsilon=0.01 k_rep=10 integrator=xpbd" "${passes}")
expect("material=silk density=0.1 stretch=2000 bend=0 drag=0.2 thickness=0.001 friction=0.3 static_friction=0.4" "${passes}")
expect("material=satin" "'material=satin': material unknown 'satin' \\(known: auto, cotton, silk, denim, leather, rubber, seed\\)")
expect("density=0 stretch=-1 friction=-0.1" "'density=0': density must be a finite number > 0 or auto \\(got 0\\) 'stretch=-1': stretch must be a finite number > 0 or auto .*'friction=-0.1': friction must be a finite number >= 0 or auto")
# values the simulator would refuse at every start: not a number, out of range, no such choice
expect("dt=-1 mass=0" "'dt=-1': dt must be a finite number > 0 \\(got -1\\) 'mass=0': mass must be a finite number > 0")
expect("k_struct=-5 damping=1e-3 k_rep=-0.5" "'k_struct=-5': k_struct must be a finite number >= 0 \\(got -5\\) 'k_rep=-0.5': k_rep must be")
expect("dt=abc" "'dt=abc': dt takes a decimal number, got 'abc'")
expect("epsilon=0x10" "'epsilon=0x10': epsilon takes a decimal number")
expect("integrator=euler" "'integrator=euler': integrator unknown 'euler' \\(known: auto, symplectic-euler, explicit-euler")
# a value no double holds, a key given twice
expect("k_rep=1e999 mass=2E+0400" "'k_rep=1e999': k_rep is out of a double's range \\(got 1e999\\) 'mass=2E\\+0400': mass is out of a double's range")
expect("k_rep=1e-400" "'k_rep=1e-400': k_rep is too small for a double \\(got 1e-400; write 0\\)")
expect("k_rep=0.001e309 k_struct=1.7976931348623157e308 gravity_x=2.2250738585072014e-308 gravity_y=1e-320 k_bend=0.0 damping=000.000e+00999" "${passes}")
expect("dt=0.002 dt=0.001" "'dt=0.001': dt is given twice")
expect("gravity_y=-9.81 dt=2e-3 mass=.5 k_bend=0" "${passes}")
expect("dt=\"0 1\"" "expected KEY=VALUE")
# entries that are good alone but not together
expect("mass=0.01 density=0.1" "density belongs to a material's cloth \\(the seed model takes mass, k_struct")
expect("friction=0.3 static_friction=0.1" "static_friction must be at least friction \\(got 0.1 < 0.3\\)")
# friction on a scene whose objects are all cloth: nothing to rub against
file(WRITE "${WORK}/alone.obj" "o Sheet\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
expect_failure("${CHECK}" "blender2ogl_add_scene(alone OBJ \"${WORK}/alone.obj\" CLOTH Sheet PARAMS friction=0.3)"
               "blender2ogl_add_scene\\(alone\\): bad PARAMS: 'friction=0.3': the scene has no colliders")
# without a checker the converter takes any key (it knows none)
expect_with("" "camera=5 look=far" "${passes}")
# names the converter would refuse or that would clash: stopped at configure time
function(expect_name name want)
  expect_failure("" "blender2ogl_add_scene(${name} OBJ \"${WORK}/absent.obj\")" "${want}")
endfunction()
expect_name("flag_" "the name must be a C\\+\\+ identifier")
expect_name("a__b" "the name must be a C\\+\\+ identifier")
expect_name("2d" "the name must be a C\\+\\+ identifier")
