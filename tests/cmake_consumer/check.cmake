# ctest's cmake_consumer: installs substratec into a temporary prefix, builds
# tests/cmake_consumer against the installed package with Ninja, and checks
# that the build is incremental: nothing to do after a build; touching one
# material reruns the command holding it and the scene listing it, no other
# (ninja -n and -d explain); editing one material of a two-material command
# recompiles it alone (one new cache entry) and leaves the other's outputs
# untouched, so nothing that consumes them reruns (restat); the scene learns
# its materials from its depfile only.
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
# Touching a material reruns the command holding it (brick and chrome share
# one) and the scene that lists it (a dependency only the scene's depfile
# declares), nothing else. A dry run also plans what consumes chrome's
# shaders (it cannot know the command will leave them as they are); the real
# run does not run it (restat).
file(TOUCH "${WORK_DIR}/src/materials/brick.json")
run(COMMAND "${NINJA}" -C "${WORK_DIR}/build" -n -d explain OUTPUT plan)
string(REGEX MATCHALL "\\[[0-9]+/[0-9]+\\][^\n]*" steps "${plan}")
list(LENGTH steps count)
if(NOT count EQUAL 3 OR NOT steps MATCHES "2 materials -> brick chrome" OR NOT steps MATCHES "scene scene.json")
  message(FATAL_ERROR "touching brick.json should rerun the command of brick and chrome, and the scene; ninja plans ${count}:\n${plan}")
endif()
if(plan MATCHES "-> felt")
  message(FATAL_ERROR "touching brick.json reruns another material:\n${plan}")
endif()
run(COMMAND "${NINJA}" -C "${WORK_DIR}/build" OUTPUT rebuilt)
if(rebuilt MATCHES "consume chrome" OR NOT rebuilt MATCHES "2 materials -> brick chrome")
  message(FATAL_ERROR "touching brick.json should rerun its command and not what consumes chrome's shaders:\n${rebuilt}")
endif()

# Editing brick recompiles brick alone: one new cache entry; chrome's outputs
# keep their old modification time, so what consumes them does not rerun.
set(cache "${out}/substratec_cache/mobile_shaders")
# Entries live in subfolders named by their key's first two hex digits
# (MaterialCache::entryPath): count the entries, not the subfolders (a new
# entry in an existing subfolder counted 0).
file(GLOB_RECURSE entriesBefore "${cache}/*.entry")
list(LENGTH entriesBefore entriesBefore)
file(GLOB chromeOutputs "${out}/mobile_shaders/chrome.*")
run(COMMAND touch -d "@1000000000" ${chromeOutputs} "${out}/chrome_forward_copy.frag")
file(READ "${out}/mobile_shaders/brick.material.glsl" brickBefore)
file(READ "${WORK_DIR}/src/materials/brick.json" brick)
string(REPLACE "\"roughness\": 0.8" "\"roughness\": 0.7" edited "${brick}")
if(edited STREQUAL brick)
  message(FATAL_ERROR "check.cmake: cannot edit brick.json's roughness")
endif()
file(WRITE "${WORK_DIR}/src/materials/brick.json" "${edited}")
run(COMMAND "${NINJA}" -C "${WORK_DIR}/build" OUTPUT rebuilt)
file(GLOB_RECURSE entriesAfter "${cache}/*.entry")
list(LENGTH entriesAfter entriesAfter)
math(EXPR added "${entriesAfter} - ${entriesBefore}")
if(NOT added EQUAL 1)
  message(FATAL_ERROR "editing brick.json should add one cache entry (one material compiled), added ${added}:\n${rebuilt}")
endif()
file(READ "${out}/mobile_shaders/brick.material.glsl" brickAfter)
if(brickAfter STREQUAL brickBefore)
  message(FATAL_ERROR "brick's shaders did not change with its roughness")
endif()
foreach(f IN LISTS chromeOutputs ITEMS "${out}/chrome_forward_copy.frag")
  file(TIMESTAMP "${f}" year "%Y" UTC)
  if(NOT year STREQUAL "2001")
    message(FATAL_ERROR "editing brick.json rewrote ${f} (${year}):\n${rebuilt}")
  endif()
endforeach()
if(rebuilt MATCHES "consume chrome")
  message(FATAL_ERROR "editing brick.json reran what consumes chrome's shaders:\n${rebuilt}")
endif()
run(COMMAND "${NINJA}" -C "${WORK_DIR}/build" -n OUTPUT settled)
if(NOT settled MATCHES "no work to do")
  message(FATAL_ERROR "not settled after editing brick.json:\n${settled}")
endif()
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
message(STATUS "cmake_consumer: installed, built, and editing one material recompiled only it")
