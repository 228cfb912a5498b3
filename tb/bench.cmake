# Benchmark, not a test: Verilator samples/s of receiver_top and the ratio to the golden model.
add_executable(bench_receiver_top ${CMAKE_CURRENT_SOURCE_DIR}/bench_receiver_top.cpp)
set_source_files_properties(${CMAKE_CURRENT_SOURCE_DIR}/bench_receiver_top.cpp PROPERTIES
  COMPILE_OPTIONS "$<$<BOOL:${RANGING_WERROR}>:-Werror>")
target_link_libraries(bench_receiver_top PRIVATE ranging_model)
target_include_directories(bench_receiver_top PRIVATE ${PROJECT_SOURCE_DIR})
target_include_directories(bench_receiver_top SYSTEM PRIVATE ${VERILATOR_ROOT}/include ${VERILATOR_ROOT}/include/vltstd)
target_compile_definitions(bench_receiver_top PRIVATE RANGING_CONFIG="${PROJECT_SOURCE_DIR}/configs/default.yaml")
verilate(bench_receiver_top SOURCES ${RANGING_GEN_DEFAULT}/rtl/receiver_top.v
  ${RANGING_RECEIVER_RTL}
  TOP_MODULE receiver_top PREFIX Vreceiver_top
  # Bench build only (the equivalence testbenches keep their settings): X values resolved once
  # at compile time and initial values not randomized (scripts/bench.sh measures the choice).
  VERILATOR_ARGS -Wno-fatal -O3 --x-assign fast --x-initial fast)

# clang++ builds of the same bench (docs/results/speed.md, "Verilator RTL"):
#   cmake --build build --target bench_receiver_top_pgo
#     ->  build/tb/bench_receiver_top_clang  (clang++ -O3, no PGO, no LTO)
#         build/tb/bench_receiver_top_pgo    (clang++ -O3, LTO, profile-guided)
# scripts/bench_pgo.cmake configures a sub-build (build/bench-pgo/) of this project with
# RANGING_BENCH_PGO=plain, then =generate, runs the instrumented bench briefly, then rebuilds it
# with RANGING_BENCH_PGO=use. Which of the two is faster depends on the CPU (2026-12-07, AMD
# EPYC: plain 1.03 M samples/s, PGO + LTO 0.93 M; 2026-12-05, another machine: PGO + LTO the
# faster), so scripts/bench.sh runs both. Without clang++ and a matching llvm-profdata: this
# build's compiler, GCC PGO + LTO only. Not part of `all` (the test build and CI never pay for
# it); on failure the plain bench_receiver_top stays (scripts/bench.sh falls back to it).
set(RANGING_BENCH_PGO "" CACHE STRING "Set by scripts/bench_pgo.cmake only: plain, generate or use")
set(RANGING_BENCH_PGO_PROFILE "" CACHE FILEPATH "Set by scripts/bench_pgo.cmake only: merged clang profile")
set(bench_build "${CMAKE_CXX_COMPILER_ID} ${CMAKE_CXX_COMPILER_VERSION}")
if(RANGING_BENCH_PGO STREQUAL "plain")
  string(APPEND bench_build ", sub-build without PGO or LTO")
elseif(RANGING_BENCH_PGO)
  # Every source of the target (the bench, the Verilated model, the Verilator runtime) is
  # instrumented and then optimized; the model libraries are built plainly.
  set(pgo_opts -flto)
  if(CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    if(RANGING_BENCH_PGO STREQUAL "generate")
      list(APPEND pgo_opts -fprofile-instr-generate)
    else()
      list(APPEND pgo_opts -fprofile-instr-use=${RANGING_BENCH_PGO_PROFILE} -Wno-profile-instr-unprofiled
           -Wno-profile-instr-out-of-date)
    endif()
  else()  # GCC: the .gcda files sit beside the objects (same sub-build, same object paths)
    if(RANGING_BENCH_PGO STREQUAL "generate")
      list(APPEND pgo_opts -fprofile-generate -fprofile-update=single)
    else()
      list(APPEND pgo_opts -fprofile-use -fprofile-partial-training -Wno-missing-profile)
    endif()
  endif()
  target_compile_options(bench_receiver_top PRIVATE ${pgo_opts})
  target_link_options(bench_receiver_top PRIVATE ${pgo_opts})
  string(APPEND bench_build ", LTO, profile-guided (${RANGING_BENCH_PGO})")
else()
  find_program(RANGING_BENCH_PGO_CXX NAMES clang++ DOC "Compiler of bench_receiver_top_pgo (clang++ if found)")
  set(pgo_bin ${CMAKE_CURRENT_BINARY_DIR}/bench_receiver_top_pgo)
  set(clang_bin ${CMAKE_CURRENT_BINARY_DIR}/bench_receiver_top_clang)
  add_custom_command(OUTPUT ${pgo_bin} BYPRODUCTS ${clang_bin}
    COMMAND ${CMAKE_COMMAND} -DSOURCE_DIR=${PROJECT_SOURCE_DIR} -DWORK_DIR=${CMAKE_BINARY_DIR}/bench-pgo
            -DOUTPUT=${pgo_bin} -DOUTPUT_PLAIN=${clang_bin} -DCLANG_CXX=${RANGING_BENCH_PGO_CXX} -DDEFAULT_CXX=${CMAKE_CXX_COMPILER}
            -P ${PROJECT_SOURCE_DIR}/scripts/bench_pgo.cmake
    # the plain bench first: it rebuilds (and so this reruns) whenever the model, RTL or bench change
    DEPENDS bench_receiver_top ${PROJECT_SOURCE_DIR}/scripts/bench_pgo.cmake ${CMAKE_CURRENT_SOURCE_DIR}/bench.cmake
    COMMENT "bench_receiver_top_pgo: clang++ build, instrumented build, training run, optimized build (scripts/bench_pgo.cmake)"
    USES_TERMINAL VERBATIM)
  add_custom_target(bench_receiver_top_pgo DEPENDS ${pgo_bin})
endif()
target_compile_definitions(bench_receiver_top PRIVATE RANGING_BENCH_BUILD="${bench_build}")
