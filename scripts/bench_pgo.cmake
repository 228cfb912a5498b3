# clang++ and profile-guided builds of tb/bench_receiver_top (target bench_receiver_top_pgo, tb/bench.cmake):
#   cmake -DSOURCE_DIR=... -DWORK_DIR=... -DOUTPUT=... -DOUTPUT_PLAIN=... [-DCLANG_CXX=clang++]
#         -DDEFAULT_CXX=... -P bench_pgo.cmake
# A sub-build of the project in WORK_DIR (hardware on, Google Benchmark programs off) builds only
# bench_receiver_top: with clang++ alone (RANGING_BENCH_PGO=plain, copied to OUTPUT_PLAIN), then
# instrumented (RANGING_BENCH_PGO=generate), a short training run on the bench's own input, then
# optimized with the profile (RANGING_BENCH_PGO=use), copied to OUTPUT. clang++ (LTO) when it
# and its llvm-profdata exist; else DEFAULT_CXX (GCC PGO + LTO) and no OUTPUT_PLAIN (it would be
# the plain bench again).
cmake_minimum_required(VERSION 3.25)
set(cxx ${DEFAULT_CXX})
unset(profdata)
if(CLANG_CXX)
  execute_process(COMMAND ${CLANG_CXX} -dumpversion OUTPUT_VARIABLE clang_version OUTPUT_STRIP_TRAILING_WHITESPACE)
  string(REGEX MATCH "^[0-9]+" clang_major "${clang_version}")
  find_program(profdata NAMES llvm-profdata-${clang_major} llvm-profdata NO_CACHE)
  if(profdata)
    set(cxx ${CLANG_CXX})
  else()
    message(STATUS "bench_pgo: no llvm-profdata for ${CLANG_CXX}; using ${DEFAULT_CXX}")
  endif()
endif()
# A sub-build configured for another compiler starts afresh (CMake would drop our -D settings).
if(EXISTS ${WORK_DIR}/CMakeCache.txt)
  file(STRINGS ${WORK_DIR}/CMakeCache.txt cached REGEX "^CMAKE_CXX_COMPILER:[A-Z]+=")
  string(REGEX REPLACE "^[^=]*=" "" cached "${cached}")
  if(NOT cached STREQUAL cxx)
    file(REMOVE_RECURSE ${WORK_DIR})
  endif()
endif()
set(profraw ${WORK_DIR}/bench.profraw)
set(profile ${WORK_DIR}/bench.profdata)

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    list(JOIN ARGN " " cmd)
    message(FATAL_ERROR "bench_pgo: failed (${rc}): ${cmd}\n(the plain tb/bench_receiver_top is unaffected)")
  endif()
endfunction()
function(stage name)
  # Verilator's CMake integration learns the list of generated files at configure time and
  # only notices a changed list (an RTL change that adds a file, such as a constant pool) one
  # build later, after the link failed: without its copy of the list the configure runs
  # Verilator and reads the list afresh.
  file(REMOVE ${WORK_DIR}/tb/CMakeFiles/bench_receiver_top.dir/Vreceiver_top.dir/Vreceiver_top_copy.cmake)
  run(${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${WORK_DIR} -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER=${cxx}
      -DRANGING_BUILD_HARDWARE=ON -DRANGING_BUILD_BENCH=OFF -DRANGING_WERROR=OFF
      -DRANGING_BENCH_PGO=${name} -DRANGING_BENCH_PGO_PROFILE=${profile})
  run(${CMAKE_COMMAND} --build ${WORK_DIR} --target bench_receiver_top)
endfunction()

file(REMOVE ${OUTPUT_PLAIN})  # never a stale one beside a new OUTPUT
if(profdata AND OUTPUT_PLAIN)
  message(STATUS "bench_pgo: ${cxx}: build without PGO or LTO")
  stage(plain)
  file(COPY_FILE ${WORK_DIR}/tb/bench_receiver_top ${OUTPUT_PLAIN})
  message(STATUS "bench_pgo: ${OUTPUT_PLAIN}")
endif()
message(STATUS "bench_pgo: ${cxx}: instrumented build")
stage(generate)
# counts of an earlier run would add to this one's (GCC merges into existing .gcda files)
file(GLOB_RECURSE old_counts ${WORK_DIR}/tb/CMakeFiles/bench_receiver_top.dir/*.gcda)
file(REMOVE ${profraw} ${old_counts})
message(STATUS "bench_pgo: training run")
# 0.3 CPU s per measurement: every stage of the model and ~150 k RTL cycles, a few seconds in all
run(${CMAKE_COMMAND} -E env LLVM_PROFILE_FILE=${profraw} ${WORK_DIR}/tb/bench_receiver_top 0.3)
if(profdata)
  run(${profdata} merge -o ${profile} ${profraw})
endif()
message(STATUS "bench_pgo: optimized build")
stage(use)
file(COPY_FILE ${WORK_DIR}/tb/bench_receiver_top ${OUTPUT})
message(STATUS "bench_pgo: ${OUTPUT}")
