# Registers one CTest test per GoogleTest *suite* of a test binary (run at
# ctest time, like gtest_discover_tests, from the binary's --gtest_list_tests).
#
# Why suites and not single tests: the tests of a suite share work inside one
# process (the GPU tests compile each material's kernels once for all the
# checks on it; the furnace tests share their tables), and a process per test
# repeats it. Measured on 2 cores: gpu_tests as 315 processes took 592 s of
# test time, as one process 122 s. The test's name is "<binary>:<suite>", so
# `ctest -R '^gpu_tests:'` selects a binary; a failure prints the suite's
# whole GoogleTest output (outputOnFailure), which names the failing test.
#
# A suite named in SPLIT becomes two tests, "<binary>:<suite>:0" and ":1", each
# one of GoogleTest's two shards of it (GTEST_TOTAL_SHARDS / GTEST_SHARD_INDEX):
# the longest suites, so that `ctest -j 2` keeps both cores busy to the end.
#
# Called by tests/CMakeLists.txt (substratec_add_gtest_suites) with
#   -DEXE=<binary> -DNAME=<binary name> -DOUT=<file to write>
#   [-DSPLIT=<suite>,<suite>...] [-DLONG=<suite>,<suite>...]
#
# LONG suites (tens of seconds) get a COST, as the split ones do, so that ctest
# starts them early in a clean clone, where it has no timing history to go by.
cmake_minimum_required(VERSION 3.25)  # script mode: IN_LIST and the other policies of the project
execute_process(COMMAND "${EXE}" --gtest_list_tests OUTPUT_VARIABLE listing RESULT_VARIABLE status
                TIMEOUT 60)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "${EXE} --gtest_list_tests failed (${status})")
endif()
string(REPLACE "\n" ";" lines "${listing}")
string(REPLACE "," ";" split "${SPLIT}")
string(REPLACE "," ";" long "${LONG}")
set(script "")
foreach(line IN LISTS lines)
  # A suite line has no leading space and ends in '.' (a "# TypeParam" comment may follow).
  if(line MATCHES "^([A-Za-z0-9_/]+)\\.( .*)?$")
    set(suite "${CMAKE_MATCH_1}")
    if(suite IN_LIST split)
      foreach(shard 0 1)
        set(test "${NAME}:${suite}:${shard}")
        set(env GTEST_TOTAL_SHARDS=2 GTEST_SHARD_INDEX=${shard})
        string(APPEND script "add_test([=[${test}]=] [=[${EXE}]=] [=[--gtest_filter=${suite}.*]=])\n")
        # COST: started first even without ctest's timing history (a clean clone),
        # so that the longest tests do not end the run on one core.
        string(APPEND script "set_tests_properties([=[${test}]=] PROPERTIES ENVIRONMENT [=[${env}]=] COST 1000)\n")
      endforeach()
      continue()
    endif()
    string(APPEND script "add_test([=[${NAME}:${suite}]=] [=[${EXE}]=] [=[--gtest_filter=${suite}.*]=])\n")
    if(suite IN_LIST long)  # started after the split suites, before the short ones
      string(APPEND script "set_tests_properties([=[${NAME}:${suite}]=] PROPERTIES COST 100)\n")
    endif()
  endif()
endforeach()
file(WRITE "${OUT}" "${script}")
