# The sanitized sub-build's tests (cmake/Sanitized.cmake, docs/fuzzing.md), included from tests/CMakeLists.txt
# where `cli_out` is defined.
#   Fuzz.*       the scene fuzzer for 60 s over a corpus seeded from scenes/ and the tests (label `fuzz`);
#   Sanitized.*  the sanitized CLI (clang, ASan + UBSan with float-cast-overflow, every check fatal) on bad
#                command lines, bad and extreme scenes, and short CPU runs: each must exit with its expected code
#                and print no sanitizer report (label `sanitized`).
# Both also carry the label `slow` (minutes, on a second build), which tools/mutate.py's CTest oracle leaves out.
# Leave both out locally with `ctest -LE 'fuzz|sanitized'` (or `-LE slow`).
if(NOT CLOUDBENCH_SANITIZED)
  return()
endif()

# Leaks are checked too: the CPU-only sanitized CLI frees everything (unlike lavapipe, see the debug preset).
set(sanitized_env "UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1"
                  "ASAN_OPTIONS=detect_leaks=1:abort_on_error=1")

# ---- Fuzz.* ------------------------------------------------------------------------------------------------------
set(fuzz_dir ${CMAKE_CURRENT_BINARY_DIR}/fuzz)
add_test(NAME Fuzz.SeedCorpus COMMAND /usr/bin/python3 ${CLOUDBENCH_ROOT}/fuzz/make_corpus.py ${CLOUDBENCH_ROOT}
                                      ${fuzz_dir}/seeds)
set_tests_properties(Fuzz.SeedCorpus PROPERTIES FIXTURES_SETUP fuzz_seeds LABELS "fuzz;slow"
                     PASS_REGULAR_EXPRESSION "make_corpus: [0-9]+ seeds")
# New inputs go to fuzz/corpus (kept between local runs), crash files to fuzz/artifacts. libFuzzer exits non-zero on
# a crash, a sanitizer report, a leak, an input slower than -timeout or memory above -rss_limit_mb (no
# PASS_REGULAR_EXPRESSION, which would make CTest ignore the exit code; its final stats print even after a crash).
add_test(NAME Fuzz.SceneParser60s
         COMMAND /bin/sh -c "mkdir -p \"$1/corpus\" \"$1/artifacts\" && exec \"$0\" -max_total_time=60 -rss_limit_mb=2048 -timeout=10 -print_final_stats=1 -dict=\"$2\" -artifact_prefix=\"$1/artifacts/\" \"$1/corpus\" \"$1/seeds\""
                 ${CLOUDBENCH_SCENE_FUZZER} ${fuzz_dir} ${CLOUDBENCH_ROOT}/fuzz/scene.dict)
set_tests_properties(Fuzz.SceneParser60s PROPERTIES FIXTURES_REQUIRED fuzz_seeds LABELS "fuzz;slow" TIMEOUT 300
                     ENVIRONMENT "${sanitized_env}"
                     FAIL_REGULAR_EXPRESSION "runtime error:|ERROR: AddressSanitizer|ERROR: LeakSanitizer|ERROR: libFuzzer|invariant broken")

# ---- Sanitized.* -------------------------------------------------------------------------------------------------
set(san_scenes ${CMAKE_CURRENT_BINARY_DIR}/sanitized_scenes)
set(san_out ${cli_out}/sanitized)
file(MAKE_DIRECTORY ${san_scenes})
set(sanitized_names)

# sanitized_case(NAME "EXIT CODES" ARG...): the sanitized CLI with ARGs exits with one of the codes, reporting nothing.
function(sanitized_case name codes)
  add_test(NAME Sanitized.${name} COMMAND ${CMAKE_COMMAND} -DCMD=${CLOUDBENCH_SANITIZED_CLI} "-DARGS=${ARGN}"
           "-DEXPECT=${codes}" -P ${CLOUDBENCH_ROOT}/cmake/ExpectCleanExit.cmake)
  set_tests_properties(Sanitized.${name} PROPERTIES LABELS "sanitized;slow" TIMEOUT 300 ENVIRONMENT "${sanitized_env}")
endfunction()

# sanitized_scene(NAME "EXIT CODES" TEXT): TEXT written as NAME.json, run for one step on the CPU.
function(sanitized_scene name codes text)
  file(WRITE ${san_scenes}/${name}.json "${text}")
  sanitized_case(${name} "${codes}" run ${san_scenes}/${name}.json --backend cpu --quiet --out ${san_out}/${name})
endfunction()

# Runs that compute: every CPU stage, the dump path, and the extremes that once crashed.
set(fast --backend cpu --quiet --set warmup_steps=0)
sanitized_case(RunCiSmallCpu 0 run ci-small --steps 3 ${fast} --out ${san_out}/run)
sanitized_case(DumpCiSmallCpu 0 dump ci-small --steps 2 ${fast} --out ${san_out}/dump)
sanitized_case(RunHugeEllipsoids 0 run ci-small --steps 2 ${fast} --set ellipsoids.size_mean=[1e10,1e10,1e10]
               --set ellipsoids.size_variance=[0,0,0] --set ellipsoids.margin=3e10 --out ${san_out}/huge-ellipsoids)
sanitized_case(RunHugeLifetime 0 run ci-small --steps 2 ${fast} --set ellipsoids.lifetime_mean=1e20
               --out ${san_out}/huge-lifetime)
sanitized_case(RunLongestShrink 0 run ci-small --steps 2 ${fast} --set ellipsoids.shrink_steps=4294967295
               --out ${san_out}/longest-shrink)
sanitized_case(RunTinyGrid 0 run ci-small --steps 2 ${fast} --set grid.size=[1,1,1] --set density.tile=1
               --set density.band=1 --out ${san_out}/tiny-grid)

# Bad command lines: exit 2 before any work.
sanitized_case(UnknownOption 2 run ci-small --frobnicate)
sanitized_case(SetWithoutEquals 2 run ci-small --set steps --quiet --out ${san_out}/usage)
sanitized_case(BackendEmptyItem 2 run ci-small --backend , --quiet --out ${san_out}/usage)
sanitized_case(BackendDuplicate 2 run ci-small --backend cpu,cpu --quiet --out ${san_out}/usage)
sanitized_case(BackendUnknown 2 run ci-small --backend cpuu --quiet --out ${san_out}/usage)

# Bad scenes and overrides: exit 3, "file: field: reason".
sanitized_case(SetOutOfRange 3 run ci-small ${fast} --set ca.p_ext=2 --out ${san_out}/bad)
sanitized_case(SetTraversalName 3 run ci-small ${fast} --set name=../../x --out ${san_out}/bad)
sanitized_case(SetTileWraps 3 run ci-small ${fast} --set density.tile=4294967295 --out ${san_out}/bad)
sanitized_case(SetVoxelCountOverflow 3 run ci-small ${fast} --set grid.size=[4294967295,4294967295,4294967295]
               --out ${san_out}/bad)
sanitized_case(SetNotAnObject 3 run ci-small ${fast} --set grid.size.x=1 --out ${san_out}/bad)
sanitized_case(SetUnknownKey 3 run ci-small ${fast} --set foo.bar=1 --out ${san_out}/bad)
sanitized_case(MissingSceneFile 3 run ${san_scenes}/no-such-scene.json ${fast} --out ${san_out}/bad)
sanitized_case(SceneIsADevice 3 run /dev/zero ${fast} --out ${san_out}/bad)
sanitized_case(SceneIsAFolder 3 run ${san_scenes} ${fast} --out ${san_out}/bad)
sanitized_scene(EmptyFile 3 "")
sanitized_scene(TruncatedJson 3 "{\"grid\": {\"size\": [8, 4,")
sanitized_scene(TopLevelArray 3 "[1, 2, 3]")
sanitized_scene(DuplicateKey 3 "{\"grid\": {\"size\": [8, 4, 8]}, \"steps\": 2, \"steps\": 3}")
sanitized_scene(WrongType 3 "{\"grid\": {\"size\": \"big\"}}")
sanitized_scene(NumberOverflow 3 "{\"grid\": {\"size\": [1e999, 4, 4]}}")
sanitized_scene(NegativeSize 3 "{\"grid\": {\"size\": [-8, 4, 4]}}")
sanitized_scene(FractionalSize 3 "{\"grid\": {\"size\": [8.5, 4, 4]}}")
sanitized_scene(ZeroSize 3 "{\"grid\": {\"size\": [8, 0, 4]}}")
sanitized_scene(HugeInteger 3 "{\"grid\": {\"size\": [8, 4, 4]}, \"steps\": 18446744073709551616}")
sanitized_scene(WarmupNotBelowSteps 3 "{\"grid\": {\"size\": [8, 4, 4]}, \"steps\": 2, \"warmup_steps\": 2}")
sanitized_scene(RendererWithoutCamera 3 "{\"grid\": {\"size\": [8, 4, 4]}, \"stages\": [\"render_splat\"]}")
sanitized_scene(WindShiftCount 3 "{\"grid\": {\"size\": [8, 4, 4]}, \"ca\": {\"wind_shift\": [[0, 0], [1, 1]]}}")
sanitized_scene(NulInString 3 "{\"grid\": {\"size\": [8, 4, 4]}, \"name\": \"a\\u0000b\"}")
string(ASCII 27 7 esc_bel)
sanitized_scene(ControlBytesInKey 3 "{\"grid\": {\"size\": [8, 4, 4]}, \"x${esc_bel}\": 1}")
string(ASCII 200 201 invalid_utf8)
sanitized_scene(InvalidUtf8 3 "{\"grid\": {\"size\": [8, 4, 4]}, \"name\": \"${invalid_utf8}\"}")
string(REPEAT "[" 2000 deep_open)
sanitized_scene(DeepNesting 3 "{\"grid\": {\"size\": [8, 4, 4]}, \"description\": ${deep_open}}")

# The whole bad-input corpus (tests/bad_inputs/, the same runner as Cli.BadInputsRefusedClearly) through the
# sanitized CLI: every report is fatal, so a sanitizer finding shows as a wrong exit code. The RLIMIT_AS cases are
# skipped: AddressSanitizer reserves far more address space than any of those limits allows.
add_test(NAME Sanitized.BadInputs
         COMMAND /usr/bin/python3 ${CLOUDBENCH_ROOT}/tests/check_bad_inputs.py --cli ${CLOUDBENCH_SANITIZED_CLI}
                 --jobs 2 --skip-rlimit)
set_tests_properties(Sanitized.BadInputs PROPERTIES LABELS "sanitized;slow" TIMEOUT 1200 ENVIRONMENT "${sanitized_env}")
