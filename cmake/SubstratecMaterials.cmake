# substrate_add_materials: compile Substrate materials as part of a build.
#
#   substrate_add_materials(TARGET <name> MATERIALS <file>...
#                           [TARGETS glsl hlsl] [PLATFORM <name>] [PLATFORMS <file>]
#                           [DIFFUSE lambert|chan2018|chan2024|eon] [CACHE <dir>]
#                           [OUTPUT_DIRECTORY <dir>] [SUBSTRATEC <path>]
#                           [MATERIALS_PER_COMMAND <n>])
#
# The materials are compiled by custom commands of up to MATERIALS_PER_COMMAND
# materials each (default 32), `substratec compile FILE... --cache DIR` with
# --depfile, so Ninja (and Make) rerun exactly the commands holding a material
# whose file (or the PLATFORMS file, or the compiler) changed. A rerun command
# takes its other materials from the content-hash cache (CACHE, default
# ${CMAKE_CURRENT_BINARY_DIR}/substratec_cache/<name>) and leaves their outputs
# untouched, so Ninja's restat rebuilds nothing that depends on them: editing
# one material recompiles one. A command pays glslang's start-up (about 0.2 s)
# once for all its materials instead of once each (docs/performance.md, "CMake:
# materials per command"); MATERIALS_PER_COMMAND 1 gives a command per material
# (no cache unless CACHE is given). <name> is a custom target (made if it does
# not exist, else made to depend on the materials) over every output. The
# outputs (docs/codegen.md) go into OUTPUT_DIRECTORY (default
# ${CMAKE_CURRENT_BINARY_DIR}/<name>) and are listed in the target's
# SUBSTRATE_OUTPUTS property; SUBSTRATE_OUTPUT_DIRECTORY holds the directory.
#
# The output names follow each material's "name", read when CMake configures:
# after renaming a material (its "name", not its file), re-run CMake.
include_guard(GLOBAL)

# What both functions take alike, from their parsed arguments (arg_*): the
# languages (`glsl`, `hlsl`, `target`), the command-line `options`, the
# `extraDeps` and the `compiler`, and arg_OUTPUT_DIRECTORY made absolute.
macro(_substratec_common_options)
  if(NOT arg_TARGETS)
    set(arg_TARGETS glsl hlsl)
  endif()
  set(glsl OFF)
  set(hlsl OFF)
  foreach(t IN LISTS arg_TARGETS)
    if(t STREQUAL "glsl" OR t STREQUAL "hlsl")
      set(${t} ON)
    else()
      message(FATAL_ERROR "${CMAKE_CURRENT_FUNCTION}(${arg_TARGET}): TARGETS takes glsl and hlsl, not '${t}'")
    endif()
  endforeach()
  if(glsl AND hlsl)
    set(target all)
  elseif(glsl)
    set(target glsl)
  else()
    set(target hlsl)
  endif()
  set(options --target ${target})
  set(extraDeps "")
  set(compiler substratec::substratec)
  if(arg_SUBSTRATEC)
    set(compiler "${arg_SUBSTRATEC}")
  endif()
  if(arg_PLATFORM)
    list(APPEND options --platform ${arg_PLATFORM})
  endif()
  if(arg_PLATFORMS)
    cmake_path(ABSOLUTE_PATH arg_PLATFORMS BASE_DIRECTORY "${CMAKE_CURRENT_SOURCE_DIR}" NORMALIZE)
    list(APPEND options --platforms "${arg_PLATFORMS}")
    list(APPEND extraDeps "${arg_PLATFORMS}")
  endif()
  if(arg_DIFFUSE)
    list(APPEND options --diffuse ${arg_DIFFUSE})
  endif()
  if(arg_CACHE)
    cmake_path(ABSOLUTE_PATH arg_CACHE BASE_DIRECTORY "${CMAKE_CURRENT_BINARY_DIR}" NORMALIZE)
    list(APPEND options --cache "${arg_CACHE}")
  endif()
  if(NOT arg_OUTPUT_DIRECTORY)
    set(arg_OUTPUT_DIRECTORY "${CMAKE_CURRENT_BINARY_DIR}/${arg_TARGET}")
  endif()
  cmake_path(ABSOLUTE_PATH arg_OUTPUT_DIRECTORY BASE_DIRECTORY "${CMAKE_CURRENT_BINARY_DIR}" NORMALIZE)
endmacro()

function(substrate_add_materials)
  cmake_parse_arguments(PARSE_ARGV 0 arg ""
                        "TARGET;PLATFORM;PLATFORMS;DIFFUSE;CACHE;OUTPUT_DIRECTORY;SUBSTRATEC;MATERIALS_PER_COMMAND"
                        "MATERIALS;TARGETS")
  if(arg_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "substrate_add_materials: unknown arguments: ${arg_UNPARSED_ARGUMENTS}")
  endif()
  if(NOT arg_TARGET)
    message(FATAL_ERROR "substrate_add_materials: TARGET <name> is required")
  endif()
  if(NOT arg_MATERIALS)
    message(FATAL_ERROR "substrate_add_materials(${arg_TARGET}): MATERIALS <file>... is required")
  endif()
  if(NOT DEFINED arg_MATERIALS_PER_COMMAND)
    set(arg_MATERIALS_PER_COMMAND 32)
  endif()
  if(NOT arg_MATERIALS_PER_COMMAND MATCHES "^[1-9][0-9]*$")
    message(FATAL_ERROR "substrate_add_materials(${arg_TARGET}): MATERIALS_PER_COMMAND takes a positive "
                        "integer, not '${arg_MATERIALS_PER_COMMAND}'")
  endif()
  list(LENGTH arg_MATERIALS materialCount)
  # A command of several materials needs the cache to recompile only what changed.
  if(NOT arg_CACHE AND arg_MATERIALS_PER_COMMAND GREATER 1 AND materialCount GREATER 1)
    set(arg_CACHE "${CMAKE_CURRENT_BINARY_DIR}/substratec_cache/${arg_TARGET}")
  endif()
  _substratec_common_options()

  set(allOutputs "")
  set(depDir "${CMAKE_CURRENT_BINARY_DIR}/substratec_depfiles/${arg_TARGET}")
  set(chunkFiles "")
  set(chunkOutputs "")
  set(chunkNames "")
  set(chunkCount 0)
  set(index 0)
  foreach(material IN LISTS arg_MATERIALS)
    math(EXPR index "${index} + 1")
    cmake_path(ABSOLUTE_PATH material BASE_DIRECTORY "${CMAKE_CURRENT_SOURCE_DIR}" NORMALIZE OUTPUT_VARIABLE file)
    if(NOT EXISTS "${file}")
      message(FATAL_ERROR "substrate_add_materials(${arg_TARGET}): ${material}: no such file")
    endif()
    file(READ "${file}" text)
    string(JSON name ERROR_VARIABLE jsonError GET "${text}" name)
    if(jsonError OR NOT name MATCHES "^[A-Za-z_][A-Za-z0-9_]*$")
      message(FATAL_ERROR "substrate_add_materials(${arg_TARGET}): ${material}: cannot read its \"name\" "
                          "(substratec compile ${material} says why)")
    endif()
    # In the order substratec writes them: its depfile's first target is this list's first.
    if(glsl)
      list(APPEND chunkOutputs "${arg_OUTPUT_DIRECTORY}/${name}.material.glsl"
           "${arg_OUTPUT_DIRECTORY}/${name}.basepass.frag" "${arg_OUTPUT_DIRECTORY}/${name}.forward.frag")
    endif()
    if(hlsl)
      list(APPEND chunkOutputs "${arg_OUTPUT_DIRECTORY}/${name}.material.hlsl"
           "${arg_OUTPUT_DIRECTORY}/${name}.basepass.ps.hlsl" "${arg_OUTPUT_DIRECTORY}/${name}.forward.ps.hlsl")
    endif()
    list(APPEND chunkOutputs "${arg_OUTPUT_DIRECTORY}/${name}.layout.json")
    list(APPEND chunkFiles "${file}")
    list(APPEND chunkNames "${name}")
    list(LENGTH chunkFiles inChunk)
    if(inChunk EQUAL arg_MATERIALS_PER_COMMAND OR index EQUAL materialCount)
      if(inChunk EQUAL 1)
        set(depfile "${depDir}/${name}.d")
        set(comment "substratec: ${material} -> ${name}")
      else()
        math(EXPR chunkCount "${chunkCount} + 1")
        set(depfile "${depDir}/${arg_TARGET}.${chunkCount}.d")
        list(JOIN chunkNames " " listed)
        set(comment "substratec: ${inChunk} materials -> ${listed}")
      endif()
      add_custom_command(
        OUTPUT ${chunkOutputs}
        COMMAND ${compiler} compile ${chunkFiles} -o "${arg_OUTPUT_DIRECTORY}" ${options} --depfile "${depfile}"
        DEPENDS ${chunkFiles} ${compiler} ${extraDeps}
        DEPFILE "${depfile}"
        COMMENT "${comment}"
        VERBATIM)
      list(APPEND allOutputs ${chunkOutputs})
      set(chunkFiles "")
      set(chunkOutputs "")
      set(chunkNames "")
    endif()
  endforeach()

  if(TARGET ${arg_TARGET})
    add_custom_target(${arg_TARGET}_substrate_materials ALL DEPENDS ${allOutputs})
    add_dependencies(${arg_TARGET} ${arg_TARGET}_substrate_materials)
  else()
    add_custom_target(${arg_TARGET} ALL DEPENDS ${allOutputs})
  endif()
  set_property(TARGET ${arg_TARGET} APPEND PROPERTY SUBSTRATE_OUTPUTS ${allOutputs})
  set_property(TARGET ${arg_TARGET} PROPERTY SUBSTRATE_OUTPUT_DIRECTORY "${arg_OUTPUT_DIRECTORY}")
endfunction()

# substrate_add_scene: build a scene (`substratec scene`, docs/scenes.md) as part of a build.
#
#   substrate_add_scene(TARGET <name> SCENE <substrate-scene/1 file>
#                       [TARGETS glsl hlsl] [PLATFORM <name>] [PLATFORMS <file>]
#                       [DIFFUSE ...] [CACHE <dir>] [OUTPUT_DIRECTORY <dir>] [SUBSTRATEC <path>])
#
# One custom command whose declared output is OUTPUT_DIRECTORY/scene.json
# (default ${CMAKE_CURRENT_BINARY_DIR}/<name>); the other files (the
# materials' shaders, the lighting and tile-classification shaders) are
# written beside it with it. Its depfile names the manifest, the PLATFORMS
# file and every material the manifest lists, so editing any of them reruns
# the scene. <name> is a custom target over scene.json (its SUBSTRATE_SCENE_REPORT
# property holds that path, SUBSTRATE_OUTPUT_DIRECTORY the directory).
function(substrate_add_scene)
  cmake_parse_arguments(PARSE_ARGV 0 arg "" "TARGET;SCENE;PLATFORM;PLATFORMS;DIFFUSE;CACHE;OUTPUT_DIRECTORY;SUBSTRATEC"
                        "TARGETS")
  if(arg_UNPARSED_ARGUMENTS OR NOT arg_TARGET OR NOT arg_SCENE)
    message(FATAL_ERROR "substrate_add_scene(TARGET <name> SCENE <file> ...): ${arg_UNPARSED_ARGUMENTS}")
  endif()
  _substratec_common_options()
  cmake_path(ABSOLUTE_PATH arg_SCENE BASE_DIRECTORY "${CMAKE_CURRENT_SOURCE_DIR}" NORMALIZE OUTPUT_VARIABLE scene)
  set(report "${arg_OUTPUT_DIRECTORY}/scene.json")
  set(depfile "${CMAKE_CURRENT_BINARY_DIR}/substratec_depfiles/${arg_TARGET}/scene.d")
  add_custom_command(
    OUTPUT "${report}"
    COMMAND ${compiler} scene "${scene}" -o "${arg_OUTPUT_DIRECTORY}" ${options} --depfile "${depfile}"
    DEPENDS "${scene}" ${compiler} ${extraDeps}
    DEPFILE "${depfile}"
    COMMENT "substratec: scene ${arg_SCENE}"
    VERBATIM)
  add_custom_target(${arg_TARGET} ALL DEPENDS "${report}")
  set_property(TARGET ${arg_TARGET} PROPERTY SUBSTRATE_SCENE_REPORT "${report}")
  set_property(TARGET ${arg_TARGET} PROPERTY SUBSTRATE_OUTPUT_DIRECTORY "${arg_OUTPUT_DIRECTORY}")
endfunction()
