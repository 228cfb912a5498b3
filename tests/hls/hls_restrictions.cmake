# ctest script: compile tests/hls/hls_restrictions.cpp against one generated HLS configuration
# and check the object for what HLS tools refuse. -DCXX= -DSRC= -DCONFIG= -DWORK=
file(MAKE_DIRECTORY ${WORK})
execute_process(
  COMMAND ${CXX} -std=c++20 -O2 -fno-exceptions -fno-rtti -fstack-usage -Wall -Wextra -Werror
          -I${SRC} "-DRANGING_HLS_CONFIG=\"${CONFIG}\"" -c ${SRC}/tests/hls/hls_restrictions.cpp
          -o ${WORK}/hls_restrictions.o
  WORKING_DIRECTORY ${WORK} RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the HLS C++ does not compile without exceptions/RTTI:\n${err}")
endif()
execute_process(COMMAND nm -u ${WORK}/hls_restrictions.o OUTPUT_VARIABLE undefined)
if(NOT undefined STREQUAL "")
  message(FATAL_ERROR "the HLS C++ calls outside itself (dynamic memory, library or throw):\n${undefined}")
endif()
execute_process(COMMAND objdump -d --no-show-raw-insn ${WORK}/hls_restrictions.o OUTPUT_VARIABLE dis)
string(REGEX MATCHALL "[ \t]call[q]?[ \t][^\n]*" calls "${dis}")
if(calls)
  message(FATAL_ERROR "calls left after flattening (recursion?):\n${calls}")
endif()
file(GLOB su ${WORK}/*.su)
file(READ ${su} frames)
string(REGEX MATCHALL "\t(dynamic|bounded)[^\n]*" dynamic "${frames}")
if(dynamic)
  message(FATAL_ERROR "stack frames of non-static size:\n${frames}")
endif()
string(REGEX MATCHALL "\tstatic" static "${frames}")
list(LENGTH static n)
if(NOT n EQUAL 3)
  message(FATAL_ERROR "expected 3 static frames (step, flush, reset), got:\n${frames}")
endif()
message(STATUS "HLS restrictions hold for ${CONFIG}: no external symbol, no call, static frames")
