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
# Called by tests/CMakeLists.txt (substratec_add_gtest_suites) with
#   -DEXE=<binary> -DNAME=<binary name> -DOUT=<file to write> [-DENVIRONMENT=<k=v;...>]
execute_process(COMMAND "${EXE}" --gtest_list_tests OUTPUT_VARIABLE listing RESULT_VARIABLE status
                TIMEOUT 60)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "${EXE} --gtest_list_tests failed (${status})")
endif()
string(REPLACE "\n" ";" lines "${listing}")
set(script "")
foreach(line IN LISTS lines)
  # A suite line has no leading space and ends in '.' (a "# TypeParam" comment may follow).
  if(line MATCHES "^([A-Za-z0-9_/]+)\\.( .*)?$")
    set(suite "${CMAKE_MATCH_1}")
    string(APPEND script "add_test([=[${NAME}:${suite}]=] [=[${EXE}]=] [=[--gtest_filter=${suite}.*]=])\n")
    if(ENVIRONMENT)
      string(APPEND script "set_tests_properties([=[${NAME}:${suite}]=] PROPERTIES ENVIRONMENT [=[${ENVIRONMENT}]=])\n")
    endif()
  endif()
endforeach()
file(WRITE "${OUT}" "${script}")
