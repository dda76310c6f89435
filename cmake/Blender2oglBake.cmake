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
# PARAMS keys must be among BLENDER2OGL_PARAM_KEYS (below), else the configure stops naming
# the scene and the key ("did you mean k_struct?" for k-struct=...).
include_guard(GLOBAL)
cmake_policy(PUSH)
cmake_policy(VERSION 3.25)  # CMP0116: depfile paths made relative for Ninja

# The keys PARAMS may bake: the simulator options its scene adapter reads from Scene::params
# (clothsim::scene_param_keys(), simulator/scene/src/scene.cpp). This list is the one the
# build checks; the test SceneAdapter.ParamKeysAreTheCMakeList fails when the two differ.
# Units: dt s, mass kg per mass, k_struct/k_bend N/m, damping N s/m, gravity_x/y/z m/s^2,
# epsilon m (collision shell), k_rep N/m (collision penalty).
set_property(GLOBAL PROPERTY BLENDER2OGL_PARAM_KEYS
  dt mass k_struct k_bend damping gravity_x gravity_y gravity_z epsilon k_rep)

# Sets ${out} to "overflow", "underflow" or "" for a decimal number (as the PARAMS check
# matched it): whether strtod() would give ERANGE, as blender2ogl --param refuses. By the
# decimal exponent of the first significant digit and its first 17 digits (DBL_MAX is
# 1.7976931348623157e308, DBL_MIN 2.2250738585072014e-308).
function(_blender2ogl_double_range value out)
  string(REGEX MATCH "^[+-]?([0-9]*)[.]?([0-9]*)([eE]([+-]?[0-9]+))?$" _ "${value}")
  set(int "${CMAKE_MATCH_1}")
  set(digits "${CMAKE_MATCH_1}${CMAKE_MATCH_2}")
  set(exp "${CMAKE_MATCH_4}")
  string(REGEX REPLACE "^[+]" "" exp "${exp}")
  if(exp MATCHES "^(-?)0*([0-9]+)$")  # (REGEX REPLACE would strip zeros again after each match)
    set(exp "${CMAKE_MATCH_1}${CMAKE_MATCH_2}")
  endif()
  string(REGEX REPLACE "^0+" "" significant "${digits}")
  string(LENGTH "${digits}" n)
  string(LENGTH "${significant}" sn)
  math(EXPR z "${n} - ${sn}")  # leading zeros
  set(result "")
  if(z LESS n)  # not zero
    string(LENGTH "${exp}" exp_len)
    if(exp_len GREATER 7)  # (beyond what the digits can move)
      if(exp MATCHES "^-")
        set(result "underflow")
      else()
        set(result "overflow")
      endif()
    else()
      if(exp STREQUAL "")
        set(exp 0)
      endif()
      string(LENGTH "${int}" int_len)
      math(EXPR e "${int_len} - 1 - ${z} + ${exp}")
      string(SUBSTRING "${digits}" ${z} 17 lead)
      string(LENGTH "${lead}" lead_len)
      while(lead_len LESS 17)
        string(APPEND lead "0")
        math(EXPR lead_len "${lead_len} + 1")
      endwhile()
      if(e GREATER 308 OR (e EQUAL 308 AND lead STRGREATER "17976931348623157"))
        set(result "overflow")
      elseif(e LESS -308 OR (e EQUAL -308 AND lead STRLESS "22250738585072014"))
        set(result "underflow")
      endif()
    endif()
  endif()
  set(${out} "${result}" PARENT_SCOPE)
endfunction()

# Stops the configure when a PARAMS entry is not KEY=VALUE with a known KEY.
function(_blender2ogl_check_params scene)
  get_property(valid GLOBAL PROPERTY BLENDER2OGL_PARAM_KEYS)
  list(JOIN valid ", " shown)
  set(problems "")
  set(seen "")
  foreach(p IN LISTS ARGN)
    if(NOT p MATCHES "^([^=]+)=(.*)$")
      string(APPEND problems "\n  '${p}': expected KEY=VALUE (e.g. dt=0.002)")
      continue()
    endif()
    set(key "${CMAKE_MATCH_1}")
    set(value "${CMAKE_MATCH_2}")
    if(key IN_LIST seen)
      string(APPEND problems "\n  '${p}': ${key} is given twice")
      continue()
    endif()
    list(APPEND seen "${key}")
    if(key IN_LIST valid)
      # The value: a number, in the range the simulator accepts (clothsim::validate_options():
      # dt, mass, epsilon > 0; stiffnesses, damping, k_rep >= 0), so that a baked value the
      # program would refuse at every start stops the configure instead.
      set(range "")
      if(value MATCHES "^[+-]?([0-9]+[.]?[0-9]*|[.][0-9]+)([eE][+-]?[0-9]+)?$")
        _blender2ogl_double_range("${value}" range)
      endif()
      if(NOT value MATCHES "^[+-]?([0-9]+[.]?[0-9]*|[.][0-9]+)([eE][+-]?[0-9]+)?$")
        string(APPEND problems "\n  '${p}': the value is not a number")
      elseif(range STREQUAL "overflow")
        string(APPEND problems "\n  '${p}': the value is out of a double's range (above 1.8e308)")
      elseif(range STREQUAL "underflow")
        string(APPEND problems "\n  '${p}': the value is too small for a double (below 2.2e-308; write 0)")
      elseif(key MATCHES "^(dt|mass|epsilon)$" AND NOT value GREATER 0)
        string(APPEND problems "\n  '${p}': ${key} must be > 0")
      elseif(key MATCHES "^(k_struct|k_bend|damping|k_rep)$" AND value LESS 0)
        string(APPEND problems "\n  '${p}': ${key} must be >= 0")
      endif()
      continue()
    endif()
    # a hint: the underscore spelling (the command line's --k-struct is PARAMS k_struct), a
    # case slip, a key cut short (mas -> mass, gravity -> gravity_x/y/z) or too long
    string(REPLACE "-" "_" fixed "${key}")
    string(TOLOWER "${fixed}" fixed)
    set(hints "")
    if(fixed IN_LIST valid)
      set(hints "${fixed}")
    else()
      string(LENGTH "${fixed}" n)
      foreach(k IN LISTS valid)
        string(LENGTH "${k}" kn)
        string(FIND "${k}" "${fixed}" at)
        string(FIND "${fixed}" "${k}" at2)
        if((n GREATER 1 AND at EQUAL 0) OR (kn GREATER 1 AND at2 EQUAL 0))
          list(APPEND hints "${k}")
        endif()
      endforeach()
    endif()
    set(hint "")
    if(hints)
      list(JOIN hints " or " hints)
      set(hint " (did you mean ${hints}?)")
    endif()
    string(APPEND problems "\n  '${key}' is not a scene parameter${hint}")
  endforeach()
  if(problems)
    message(FATAL_ERROR "blender2ogl_add_scene(${scene}): bad PARAMS:${problems}\n"
                        "Valid keys (underscores, as the simulator reads them): ${shown}")
  endif()
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
  _blender2ogl_check_params(${name} ${B2O_PARAMS})
  get_filename_component(obj "${B2O_OBJ}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
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
