# The sanitized sub-build (docs/fuzzing.md): the `cloudbench` CLI and the scene fuzzer compiled with
# Debian's clang under AddressSanitizer and UBSan (float-cast-overflow included), every check fatal. A workflow
# preset has one configure preset, so the release build drives this second build of the same source tree as an
# ExternalProject in build/<preset>/sanitized. Only the CPU backend is built there: the bad-input tests are about
# loading and the CPU stages, and the GL/VK host code under ASan would double the build for drivers that leak.
#
# Sets CLOUDBENCH_SANITIZED_CLI and CLOUDBENCH_SCENE_FUZZER (paths, for tests/sanitized.cmake and other runners).
include(ExternalProject)

# Debian 12's clang 16: clang 14 cannot compile the project, as libstdc++ 12 offers std::expected only when
# __cpp_concepts >= 202002L. Clang 16 implements what that value stands for (P0848, conditionally trivial special
# members) but still reports 201907L (until clang 19), so the flags below raise it.
find_program(CLOUDBENCH_CLANGXX NAMES clang++-16)
cloudbench_require(CLOUDBENCH_CLANGXX "clang++ 16 with the sanitizer and libFuzzer runtimes (or configure with -DCLOUDBENCH_SANITIZED=OFF)"
                   "clang-16 libclang-rt-16-dev")

cmake_host_system_information(RESULT cloudbench_cores QUERY NUMBER_OF_LOGICAL_CORES)
set(CLOUDBENCH_SANITIZED_JOBS ${cloudbench_cores} CACHE STRING "Parallel jobs of the sanitized sub-build")

set(cloudbench_sanitized_dir ${CMAKE_BINARY_DIR}/sanitized)
set(cloudbench_sanitized_flags
    "-fsanitize=address,undefined,float-cast-overflow -fno-sanitize-recover=all -fno-omit-frame-pointer -fsanitize=fuzzer-no-link -Wno-unknown-warning-option -U__cpp_concepts -D__cpp_concepts=202002L")
set(cloudbench_sanitized_cache
    -DCMAKE_CXX_COMPILER:FILEPATH=${CLOUDBENCH_CLANGXX}
    -DCMAKE_BUILD_TYPE:STRING=Debug
    # -O1: optimised enough that `run ci-small` takes seconds, and asserts stay on. Line tables only: what the
    # sanitizers' stack traces print (file and line), at less compile time than full debug information.
    "-DCMAKE_CXX_FLAGS_DEBUG:STRING=-O1 -gline-tables-only"
    "-DCMAKE_CXX_FLAGS:STRING=${cloudbench_sanitized_flags}"
    -DCLOUDBENCH_SANITIZED:BOOL=OFF
    -DCLOUDBENCH_BUILD_FUZZER:BOOL=ON
    -DCLOUDBENCH_WITH_GL:BOOL=OFF
    -DCLOUDBENCH_WITH_VK:BOOL=OFF
    -DCLOUDBENCH_BUILD_TESTS:BOOL=OFF
    -DCLOUDBENCH_BUILD_BENCHMARKS:BOOL=OFF
    -DCLOUDBENCH_NATIVE:BOOL=${CLOUDBENCH_NATIVE}
    -DCLOUDBENCH_UNITY_BUILD:BOOL=${CLOUDBENCH_UNITY_BUILD})
if(CMAKE_CXX_COMPILER_LAUNCHER)
  list(APPEND cloudbench_sanitized_cache "-DCMAKE_CXX_COMPILER_LAUNCHER:STRING=${CMAKE_CXX_COMPILER_LAUNCHER}")
endif()

set(CLOUDBENCH_SANITIZED_CLI ${cloudbench_sanitized_dir}/cloudbench)
set(CLOUDBENCH_SCENE_FUZZER ${cloudbench_sanitized_dir}/cloudbench_scene_fuzzer)
ExternalProject_Add(cloudbench_sanitized
  SOURCE_DIR ${CMAKE_SOURCE_DIR}
  BINARY_DIR ${cloudbench_sanitized_dir}
  PREFIX ${CMAKE_BINARY_DIR}/sanitized-ep
  CMAKE_GENERATOR ${CMAKE_GENERATOR}
  CMAKE_CACHE_ARGS ${cloudbench_sanitized_cache}
  BUILD_COMMAND ${CMAKE_COMMAND} --build <BINARY_DIR> --target cloudbench cloudbench_scene_fuzzer
                -j ${CLOUDBENCH_SANITIZED_JOBS}
  BUILD_ALWAYS ON
  BUILD_BYPRODUCTS ${CLOUDBENCH_SANITIZED_CLI} ${CLOUDBENCH_SCENE_FUZZER}
  INSTALL_COMMAND ""
  USES_TERMINAL_BUILD ON)
