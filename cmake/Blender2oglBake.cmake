# blender2ogl_add_scene(<name> OBJ <file.obj>
#                       [CLOTH <object>...] [PIN <object:x,y,z>...] [PARAMS <key=value>...]
#                       [DEPENDS <extra files>...] [COMBINED] [NO_REVERSE_MAP] [ALLOW_MISSING])
#
# ALLOW_MISSING passes --allow-missing: a missing .mtl or texture is a warning, not an error.
#
# Bakes a model at build time into a static library target scene_<name> (ALIAS
# blender2ogl::scene::<name>) whose header <name>.h declares b2o::gen::<name>::scene.
# The generated files go to ${CMAKE_CURRENT_BINARY_DIR}/blender2ogl/<name>/. The bake re-runs
# when the .obj, its .mtl, a texture (known from the .obj's mtllib and the .mtl's map_Kd at
# configure time, and exactly from the converter's depfile at build time), a DEPENDS file or
# the converter itself changes, and not otherwise.
#
# Inside the clothsim tree the converter is the blender2ogl target; an installed package
# provides the imported target blender2ogl::blender2ogl (find_package(blender2ogl)).
#
# PARAMS entries are checked by the program that reads the scene (BLENDER2OGL_PARAMS_CHECK,
# below): in the clothsim tree and package, an unknown key or a value the simulator would
# refuse stops the configure naming the scene and the key ("did you mean k_struct?").
include_guard(GLOBAL)
cmake_policy(PUSH)
cmake_policy(VERSION 3.25)  # CMP0116: depfile paths made relative for Ninja

# PARAMS are KEY=VALUE entries baked as text into Scene::params for the program that reads
# the scene. The converter knows no keys: a consumer that does sets the global property
# BLENDER2OGL_PARAMS_CHECK to a command that takes `--colliders N` (the OBJ's objects that are
# not CLOTH, when its `o` lines name them) and then the entries as arguments, and exits
# non-zero (saying why on stderr) when one is wrong; the clothsim package sets its checker there.
function(_blender2ogl_check_params scene colliders)
  set(problems "")
  set(seen "")
  foreach(p IN LISTS ARGN)
    if(NOT p MATCHES "^([A-Za-z_][A-Za-z0-9_-]*)=([^ \t\"'\\]+)$")
      string(APPEND problems "\n  '${p}': expected KEY=VALUE (e.g. dt=0.002; no spaces or quotes in the value)")
      continue()
    endif()
    if(CMAKE_MATCH_1 IN_LIST seen)
      string(APPEND problems "\n  '${p}': ${CMAKE_MATCH_1} is given twice")
    endif()
    list(APPEND seen "${CMAKE_MATCH_1}")
  endforeach()
  get_property(check GLOBAL PROPERTY BLENDER2OGL_PARAMS_CHECK)
  if(NOT problems AND check AND ARGN)
    set(count "")
    if(NOT colliders STREQUAL "")
      set(count --colliders ${colliders})
    endif()
    execute_process(COMMAND ${check} ${count} ${ARGN} RESULT_VARIABLE rc ERROR_VARIABLE err OUTPUT_QUIET)
    if(NOT rc EQUAL 0)
      string(STRIP "${err}" err)
      string(APPEND problems "\n${err}")
    endif()
  endif()
  if(problems)
    message(FATAL_ERROR "blender2ogl_add_scene(${scene}): bad PARAMS:${problems}")
  endif()
endfunction()

# The OBJ's objects that are not cloth (by its `o` lines), or "" when it names none.
function(_blender2ogl_count_colliders obj cloths out)
  file(STRINGS "${obj}" objects REGEX "^o ")
  set(count "")
  if(objects)
    set(count 0)
    foreach(line IN LISTS objects)
      string(SUBSTRING "${line}" 2 -1 object)
      string(STRIP "${object}" object)
      if(NOT object IN_LIST cloths)
        math(EXPR count "${count} + 1")
      endif()
    endforeach()
  endif()
  set(${out} "${count}" PARENT_SCOPE)
endfunction()

function(blender2ogl_add_scene name)
  cmake_parse_arguments(PARSE_ARGV 1 B2O "COMBINED;NO_REVERSE_MAP;ALLOW_MISSING" "OBJ" "CLOTH;PIN;PARAMS;DEPENDS")
  if(B2O_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "blender2ogl_add_scene(${name}): unknown arguments: ${B2O_UNPARSED_ARGUMENTS}")
  endif()
  if(NOT name MATCHES "^[A-Za-z][A-Za-z0-9_]*$" OR name MATCHES "__" OR name MATCHES "_$")
    message(FATAL_ERROR "blender2ogl_add_scene(${name}): the name must be a C++ identifier (letters, digits, single _ inside)")
  endif()
  if(TARGET scene_${name})
    message(FATAL_ERROR "blender2ogl_add_scene(${name}): a scene of this name was added already (target scene_${name})")
  endif()
  if(NOT B2O_OBJ)
    message(FATAL_ERROR "blender2ogl_add_scene(${name}): OBJ <file> is required")
  endif()
  get_filename_component(obj "${B2O_OBJ}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
  set(colliders "")
  if(EXISTS "${obj}" AND NOT IS_DIRECTORY "${obj}")
    _blender2ogl_count_colliders("${obj}" "${B2O_CLOTH}" colliders)
  endif()
  _blender2ogl_check_params(${name} "${colliders}" ${B2O_PARAMS})
  if(NOT EXISTS "${obj}" OR IS_DIRECTORY "${obj}")
    message(FATAL_ERROR "blender2ogl_add_scene(${name}): ${obj}: no such model file")
  endif()
  if(NOT TARGET blender2ogl::blender2ogl)
    message(FATAL_ERROR "blender2ogl_add_scene(${name}): the converter target blender2ogl::blender2ogl is missing (find_package(blender2ogl))")
  endif()
  get_target_property(converter blender2ogl::blender2ogl ALIASED_TARGET)
  if(NOT converter)
    set(converter blender2ogl::blender2ogl)
  endif()
  get_target_property(converter_imported ${converter} IMPORTED)

  # Inputs known at configure time: the .mtl files of mtllib lines and their map_Kd images.
  get_filename_component(folder "${obj}" DIRECTORY)
  set(inputs "${obj}")
  file(STRINGS "${obj}" mtl_lines REGEX "^[ \t]*mtllib[ \t]")
  foreach(line IN LISTS mtl_lines)
    string(REGEX REPLACE "^[ \t]*mtllib[ \t]+" "" mtl "${line}")
    string(STRIP "${mtl}" mtl)
    if(EXISTS "${folder}/${mtl}")
      list(APPEND inputs "${folder}/${mtl}")
      get_filename_component(mtl_folder "${folder}/${mtl}" DIRECTORY)
      file(STRINGS "${folder}/${mtl}" map_lines REGEX "^[ \t]*map_Kd[ \t]")
      foreach(map IN LISTS map_lines)
        string(STRIP "${map}" map)
        string(REGEX REPLACE "^.*[ \t]" "" image "${map}")
        string(REPLACE "\\" "/" image "${image}")
        if(EXISTS "${mtl_folder}/${image}")
          list(APPEND inputs "${mtl_folder}/${image}")
        endif()
      endforeach()
    endif()
  endforeach()
  foreach(extra IN LISTS B2O_DEPENDS)
    get_filename_component(extra "${extra}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
    list(APPEND inputs "${extra}")
  endforeach()
  list(REMOVE_DUPLICATES inputs)

  set(args -n ${name})
  if(NOT B2O_NO_REVERSE_MAP)
    list(APPEND args -r)
  endif()
  if(B2O_ALLOW_MISSING)
    list(APPEND args --allow-missing)
  endif()
  foreach(c IN LISTS B2O_CLOTH)
    list(APPEND args -a ${c})
  endforeach()
  foreach(p IN LISTS B2O_PIN)
    list(APPEND args -p ${p})
  endforeach()
  foreach(p IN LISTS B2O_PARAMS)
    list(APPEND args --param ${p})
  endforeach()

  set(out "${CMAKE_CURRENT_BINARY_DIR}/blender2ogl/${name}")
  if(B2O_COMBINED)
    list(APPEND args -c)
    set(outputs "${out}/${name}.h")
  else()
    # The bulk bytes go to <name>.<hash>.bin, named by the header (a changed .bin is a changed
    # header, which the .cpp and .S include: their depfiles re-build them).
    set(outputs "${out}/${name}.h" "${out}/${name}.cpp" "${out}/${name}.S")
  endif()
  # The converter as a file dependency (re-bake when it is rebuilt) and, inside the
  # project, as a target dependency (build it first).
  set(converter_deps "$<TARGET_FILE:${converter}>")
  if(NOT converter_imported)
    list(APPEND converter_deps ${converter})
  endif()
  file(RELATIVE_PATH shown "${CMAKE_SOURCE_DIR}" "${obj}")
  add_custom_command(
    OUTPUT ${outputs}
    COMMAND "$<TARGET_FILE:${converter}>" ${args} -t "${out}" --depfile "${out}/${name}.d" "${obj}"
    DEPENDS ${inputs} ${converter_deps}
    DEPFILE "${out}/${name}.d"
    COMMENT "blender2ogl: baking scene ${name} from ${shown}"
    VERBATIM)

  add_library(scene_${name} STATIC ${outputs})
  add_library(blender2ogl::scene::${name} ALIAS scene_${name})
  # The .S (through the header) finds <name>.<hash>.bin through this include directory.
  target_include_directories(scene_${name} PUBLIC "${out}")
  if(TARGET blender2ogl::scene_types)
    target_link_libraries(scene_${name} PUBLIC blender2ogl::scene_types)
  endif()
  if(COMMAND clothsim_warnings)
    clothsim_warnings(scene_${name})
  endif()
  set_target_properties(scene_${name} PROPERTIES LINKER_LANGUAGE CXX)
endfunction()

cmake_policy(POP)
