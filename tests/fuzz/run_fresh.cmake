# Runs a short fuzzing test from a fresh output corpus:
#   cmake -DCORPUS=DIR -P run_fresh.cmake -- FUZZER ARGS...
# DIR (where the fuzzer writes the inputs it finds, the first corpus folder
# in ARGS) is emptied first. Without that it grows with every run of the
# tests, and once replaying it takes longer than the test's time budget the
# fuzzer stops before it fuzzes anything ("run interrupted") and the test
# fails under load for no reason in the code. The seed corpora stay as they
# are in the source tree; a long run keeps its corpus elsewhere
# (docs/robustness.md).
if(NOT CORPUS)
  message(FATAL_ERROR "run_fresh.cmake: -DCORPUS=<dir> is required")
endif()
set(_command "")
set(_after_dashes FALSE)
math(EXPR _last "${CMAKE_ARGC} - 1")
foreach(_i RANGE 0 ${_last})
  if(_after_dashes)
    list(APPEND _command "${CMAKE_ARGV${_i}}")
  elseif(CMAKE_ARGV${_i} STREQUAL "--")
    set(_after_dashes TRUE)
  endif()
endforeach()
list(LENGTH _command _count)  # (not if(NOT _command): a command "false" would read as false)
if(_count EQUAL 0)
  message(FATAL_ERROR "run_fresh.cmake: no command after --")
endif()
file(REMOVE_RECURSE "${CORPUS}")
file(MAKE_DIRECTORY "${CORPUS}")
execute_process(COMMAND ${_command} RESULT_VARIABLE _rc)
if(NOT _rc EQUAL 0)
  message(FATAL_ERROR "the fuzzer exited with ${_rc}")
endif()
