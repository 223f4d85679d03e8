# libFuzzer targets (option SG_FUZZ, clang only; see the `fuzz` preset and docs/reliability.md).
# Every stereoguard library is then built with -fsanitize=fuzzer-no-link,address,undefined (see
# sg_target_options.cmake); each target links libFuzzer's main and is registered with CTest.
set(SG_FUZZ_RUNS 20000 CACHE STRING "Executions per fuzz target in its CTest test (label fuzz)")
set(SG_FUZZ_SOURCE_DIR ${PROJECT_SOURCE_DIR}/tests/fuzz)

# sg_fuzz_target(<name> DEPS ...): fuzz_<name> from tests/fuzz/fuzz_<name>.cpp, seeded from
# tests/fuzz/corpus/<name>/. The CTest test runs SG_FUZZ_RUNS executions; new inputs go to
# <build>/fuzz/corpus/<name> (never into the repository), crashes to <build>/fuzz/artifacts/.
function(sg_fuzz_target name)
  cmake_parse_arguments(ARG "" "" "DEPS" ${ARGN})
  set(target fuzz_${name})
  add_executable(${target} ${SG_FUZZ_SOURCE_DIR}/${target}.cpp ${SG_FUZZ_SOURCE_DIR}/fuzz_input.cpp)
  target_link_libraries(${target} PRIVATE ${ARG_DEPS})
  target_include_directories(${target} PRIVATE ${SG_FUZZ_SOURCE_DIR})
  sg_target_options(${target})
  target_link_options(${target} PRIVATE -fsanitize=fuzzer)
  set(work ${PROJECT_BINARY_DIR}/fuzz/corpus/${name})
  set(artifacts ${PROJECT_BINARY_DIR}/fuzz/artifacts)
  file(MAKE_DIRECTORY ${work} ${artifacts})
  add_test(NAME ${target}
    COMMAND ${target} -runs=${SG_FUZZ_RUNS} -timeout=60 -rss_limit_mb=2048 -print_final_stats=1
            -artifact_prefix=${artifacts}/${name}- ${work} ${SG_FUZZ_SOURCE_DIR}/corpus/${name})
  set_tests_properties(${target} PROPERTIES LABELS fuzz
    ENVIRONMENT "ASAN_OPTIONS=detect_leaks=1;UBSAN_OPTIONS=print_stacktrace=1")
  add_dependencies(sg_fuzz_targets ${target})
endfunction()

add_custom_target(sg_fuzz_targets)
