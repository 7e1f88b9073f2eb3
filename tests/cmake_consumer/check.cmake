# ctest's cmake_consumer: installs substratec into a temporary prefix, builds
# tests/cmake_consumer against the installed package with Ninja, and checks
# that the build is incremental: nothing to do after a build; touching one
# material reruns its command and the scene listing it, no other (ninja -n and
# -d explain); the scene learns its materials from its depfile only.
#
#   cmake -DBUILD_DIR=<substratec build> -DSOURCE_DIR=<tests/cmake_consumer>
#         -DWORK_DIR=<scratch> -DNINJA=<ninja> -P check.cmake
foreach(v BUILD_DIR SOURCE_DIR WORK_DIR NINJA)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "check.cmake: -D${v}=... is required")
  endif()
endforeach()

function(run)
  cmake_parse_arguments(PARSE_ARGV 0 arg "" "OUTPUT" "COMMAND")
  execute_process(COMMAND ${arg_COMMAND} RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(NOT status EQUAL 0)
    string(REPLACE ";" " " line "${arg_COMMAND}")
    message(FATAL_ERROR "failed (${status}): ${line}\n${out}")
  endif()
  if(arg_OUTPUT)
    set(${arg_OUTPUT} "${out}" PARENT_SCOPE)
  endif()
endfunction()

file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}")
# A copy of the consumer: the check touches its files.
file(COPY "${SOURCE_DIR}/" DESTINATION "${WORK_DIR}/src" PATTERN "check.cmake" EXCLUDE)

run(COMMAND "${CMAKE_COMMAND}" --install "${BUILD_DIR}" --prefix "${WORK_DIR}/prefix")
foreach(f bin/substratec share/substratec/runtime_shaders/substrate_lighting.h
          share/substratec/schema/substrate-scene.schema.json lib/cmake/substratec/substratecConfig.cmake
          lib/cmake/substratec/substratecConfigVersion.cmake lib/cmake/substratec/SubstratecMaterials.cmake)
  if(NOT EXISTS "${WORK_DIR}/prefix/${f}")
    message(FATAL_ERROR "not installed: ${f}")
  endif()
endforeach()

run(COMMAND "${CMAKE_COMMAND}" -S "${WORK_DIR}/src" -B "${WORK_DIR}/build" -G Ninja
            "-DCMAKE_MAKE_PROGRAM=${NINJA}" "-DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix" OUTPUT configured)
if(NOT configured MATCHES "mobile_shaders: 14 outputs")
  message(FATAL_ERROR "expected 14 outputs for two materials in both languages:\n${configured}")
endif()
run(COMMAND "${NINJA}" -C "${WORK_DIR}/build" OUTPUT built)
set(out "${WORK_DIR}/build")
foreach(f mobile_shaders/brick.material.glsl mobile_shaders/brick.basepass.ps.hlsl mobile_shaders/chrome.layout.json
          pc_shaders/felt.forward.frag pc_shaders/felt.layout.json)
  if(NOT EXISTS "${out}/${f}")
    message(FATAL_ERROR "not built: ${f}\n${built}")
  endif()
endforeach()
if(EXISTS "${out}/pc_shaders/felt.material.hlsl")
  message(FATAL_ERROR "pc_shaders asked for GLSL only")
endif()
# Built for the platforms asked: chrome's F90 is allowed on mobile, felt keeps its fuzz on pc-high.
file(READ "${out}/pc_shaders/felt.material.glsl" felt)
if(NOT felt MATCHES "#define SUBSTRATE_USE_FUZZ 1")
  message(FATAL_ERROR "felt lost its fuzz on pc-high")
endif()

# Incremental: nothing to do, then exactly the touched material.
run(COMMAND "${NINJA}" -C "${WORK_DIR}/build" -n OUTPUT again)
if(NOT again MATCHES "no work to do")
  message(FATAL_ERROR "a second build is not empty:\n${again}")
endif()
if(NOT EXISTS "${out}/yard_lighting/scene.json" OR NOT EXISTS "${out}/yard_lighting/yard.lighting_simple.comp")
  message(FATAL_ERROR "the scene was not built:\n${built}")
endif()
# Touching a material reruns its own command and the scene that lists it (a
# dependency only the scene's depfile declares), nothing else.
file(TOUCH "${WORK_DIR}/src/materials/brick.json")
run(COMMAND "${NINJA}" -C "${WORK_DIR}/build" -n -d explain OUTPUT plan)
string(REGEX MATCHALL "\\[[0-9]+/[0-9]+\\][^\n]*" steps "${plan}")
list(LENGTH steps count)
if(NOT count EQUAL 2 OR NOT steps MATCHES "brick.json -> brick" OR NOT steps MATCHES "scene scene.json")
  message(FATAL_ERROR "touching brick.json should rerun brick's command and the scene; ninja plans ${count}:\n${plan}")
endif()
if(plan MATCHES "-> chrome|-> felt")
  message(FATAL_ERROR "touching brick.json reruns another material:\n${plan}")
endif()
run(COMMAND "${NINJA}" -C "${WORK_DIR}/build" OUTPUT rebuilt)
# Felt alone: one command.
file(TOUCH "${WORK_DIR}/src/materials/felt.json")
run(COMMAND "${NINJA}" -C "${WORK_DIR}/build" -n OUTPUT plan)
string(REGEX MATCHALL "\\[[0-9]+/[0-9]+\\][^\n]*" steps "${plan}")
list(LENGTH steps count)
if(NOT count EQUAL 1 OR NOT steps MATCHES "felt")
  message(FATAL_ERROR "touching felt.json should rerun felt's command only:\n${plan}")
endif()
run(COMMAND "${NINJA}" -C "${WORK_DIR}/build" OUTPUT rebuilt)
run(COMMAND "${NINJA}" -C "${WORK_DIR}/build" -n OUTPUT settled)
if(NOT settled MATCHES "no work to do")
  message(FATAL_ERROR "not settled after the rebuild:\n${settled}")
endif()
message(STATUS "cmake_consumer: installed, built, and touching one material rebuilt only it")
