# `cloudbench report`: a page from a real small run, conformance check and sweep of ci-small
# and a synthetic history, loaded in headless chromium (skipped, 77, without it; CI installs it through
# tools/debian-packages.txt). Included from tests/CMakeLists.txt, where `cli` and `cli_out` are defined.
add_test(NAME Cli.HtmlReport
         COMMAND /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/check_html_report.py ${cli} ${cli_out}/html ci-small)
set_tests_properties(Cli.HtmlReport PROPERTIES TIMEOUT 300 SKIP_RETURN_CODE 77 PASS_REGULAR_EXPRESSION "html report: ok")
# Bad inputs exit 3 with the file named; no input at all is a usage error (2).
add_test(NAME Cli.ReportMissingFileExits3 COMMAND ${CMAKE_COMMAND} -DCMD=${cli}
         "-DARGS=report;${cli_out}/html-bad/missing.json;-o;${cli_out}/html-bad/r.html" -DEXPECT=3 ${expect_exit})
set_tests_properties(Cli.ReportMissingFileExits3 PROPERTIES PASS_REGULAR_EXPRESSION
                     "missing.json: cannot read the file: No such file or directory")
add_test(NAME Cli.ReportNotJsonExits3 COMMAND ${CMAKE_COMMAND} -DCMD=${cli}
         "-DARGS=report;${CMAKE_CURRENT_SOURCE_DIR}/check_html_report.py;-o;${cli_out}/html-bad/r.html" -DEXPECT=3
         ${expect_exit})
set_tests_properties(Cli.ReportNotJsonExits3 PROPERTIES PASS_REGULAR_EXPRESSION "check_html_report.py: not a results.json, a conform.json, an accuracy.json, a sweep.json or a perf compare --json file: line 1, column 1: malformed JSON")
add_test(NAME Cli.ReportUnknownFormatExits3 COMMAND ${CMAKE_COMMAND} -DCMD=${cli}
         "-DARGS=report;${CLOUDBENCH_ROOT}/docs/seed-timings.json;-o;${cli_out}/html-bad/r.html" -DEXPECT=3 ${expect_exit})
set_tests_properties(Cli.ReportUnknownFormatExits3 PROPERTIES PASS_REGULAR_EXPRESSION
                     "seed-timings.json: not a results.json, a conform.json, an accuracy.json, a sweep.json or a perf compare --json file [(].format. is .cloudbench-seed-timings/1.[)]")
add_test(NAME Cli.ReportNoInputExits2 COMMAND ${CMAKE_COMMAND} -DCMD=${cli} "-DARGS=report" -DEXPECT=2 ${expect_exit})
add_test(NAME Cli.ReportWritesNothingOnBadInput COMMAND /bin/sh -c "! test -e \"$0\"" ${cli_out}/html-bad/r.html)
set_tests_properties(Cli.ReportWritesNothingOnBadInput PROPERTIES DEPENDS
                     "Cli.ReportMissingFileExits3;Cli.ReportNotJsonExits3;Cli.ReportUnknownFormatExits3")
# The regression gate's verdict on the page: a `perf compare --json` file and a kept interleave's folder (the
# flagged stage, its mark, the verdict's exit code, the failed runs), bad files refused naming file and field, and
# `perf compare --interleave --plant` (recorded in interleave.json and the verdict; bad values exit 2).
add_test(NAME Cli.ReportPerfCompare
         COMMAND /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/check_report_compare.py ${cli} ${cli_out}/report-compare)
set_tests_properties(Cli.ReportPerfCompare PROPERTIES TIMEOUT 300 PASS_REGULAR_EXPRESSION "report compare: ok")
