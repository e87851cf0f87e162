# Performance tracking (`cloudbench perf`, docs/cli.md): the
# statistics against SciPy, the history's records, and the CI gate on this
# machine (an identical build passes, a planted slowdown fails with exit 6).
# Included from tests/CMakeLists.txt, where `cli` and `cli_out` are defined.
foreach(case compare rounds clock runs instructions inputs history changepoints verdicts gbench)
  add_test(NAME Perf.Stats.${case}
           COMMAND /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/check_perf_stats.py ${cli} ${cli_out}/perf-${case} ${case})
  set_tests_properties(Perf.Stats.${case} PROPERTIES PASS_REGULAR_EXPRESSION ": ok" SKIP_RETURN_CODE 77 TIMEOUT 300)
endforeach()
add_test(NAME Perf.Record
         COMMAND /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/check_perf_record.py ${cli} ${cli_out}/perf-record)
set_tests_properties(Perf.Record PROPERTIES PASS_REGULAR_EXPRESSION "perf record: ok" TIMEOUT 600)
# CI tracking from a history: records before and after a planted 1.5x step; perf history finds it in that
# stage alone and perf compare of the records flags it alone. It runs alone (RUN_SERIAL): records are taken at
# different times, so unlike the interleaved gate's pairs they cannot cancel a machine whose speed moves by 2x
# between them (beside another test, region's unslowed records had a median of 0.085 ms, against 0.045 ms alone,
# and the step was found three records late), and the test is of the tools' rules, not of the machine. When the
# machine's speed still moved between one side's records by more than the step (1.5x), it skips, saying so.
add_test(NAME Perf.HistoryStep
         COMMAND /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/check_perf_history_step.py ${cli} ${cli_out}/perf-history-step)
set_tests_properties(Perf.HistoryStep PROPERTIES PASS_REGULAR_EXPRESSION "perf history step: ok" TIMEOUT 300 SKIP_RETURN_CODE 77
                     RUN_SERIAL TRUE)
# kept: the verdict from a kept folder is the live one (a failed run fails both; a kept folder with no run is refused).
foreach(case identical slowdown kept)
  add_test(NAME Perf.Gate.${case}
           COMMAND /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/check_perf_gate.py ${cli} ${cli_out}/perf-gate-${case} ${case})
  # Two gate runs side by side would each see the other's load, so they run one at a time.
  set_tests_properties(Perf.Gate.${case} PROPERTIES PASS_REGULAR_EXPRESSION "perf gate ${case}: ok" TIMEOUT 600
                       RESOURCE_LOCK perf_gate)
endforeach()
# The gate's decision rules at their boundaries through the command: the rounds rule (alpha exactly at
# m (1 + K + K(K-1)/2) 2^-K and one ulp above), and '?' with Holm's factor in the table, the warning and --json.
foreach(case rounds unjudged)
  add_test(NAME Perf.Boundary.${case}
           COMMAND /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/check_perf_boundaries.py ${cli} ${cli_out}/perf-boundary-${case} ${case})
  set_tests_properties(Perf.Boundary.${case} PROPERTIES PASS_REGULAR_EXPRESSION "perf boundaries ${case}: ok" TIMEOUT 300)
endforeach()
