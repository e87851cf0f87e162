# Coherent output folders (docs/results.md#output-folders): one command per folder at a time (a lock),
# and a run's outputs never mixed with the previous run's (a journal of written files, removed at the next start).
# Included from tests/CMakeLists.txt, where `cli` and `cli_out` are defined.
set(outputs_py ${CMAKE_CURRENT_SOURCE_DIR})

# Test that every writing command exits 1 at once, writing nothing, while another holds the folder's lock.
set(outputs_locked_commands
    Run "run|ci-small" Dump "dump|ci-small" Conform "conform|ci-small" Accuracy "accuracy|ci-small"
    Sweep "sweep|ci-small|--vary|shade.resolution=1,2")
while(outputs_locked_commands)
  list(POP_FRONT outputs_locked_commands name args)
  string(REPLACE "|" ";" args "${args}")
  add_test(NAME Cli.${name}LockedFolderExits1
           COMMAND /usr/bin/python3 ${outputs_py}/check_output_lock.py ${cli} ${cli_out}/locked-${name} held ${args})
  set_tests_properties(Cli.${name}LockedFolderExits1 PROPERTIES TIMEOUT 60 PASS_REGULAR_EXPRESSION
                       "refused while the lock is held")
endwhile()

# Test that of two runs into one folder, the second is refused while the first holds it, and the folder ends
# with the first run alone.
add_test(NAME Cli.ConcurrentRunsOneProceeds
         COMMAND /usr/bin/python3 ${outputs_py}/check_output_lock.py ${cli} ${cli_out}/concurrent concurrent)
set_tests_properties(Cli.ConcurrentRunsOneProceeds PROPERTIES TIMEOUT 180 PASS_REGULAR_EXPRESSION
                     "one run proceeded, the other was refused")

# Test that a run killed (SIGKILL) at 50 random points always leaves a coherent folder, and the next run takes it
# over. The seed is printed; replay with --seed.
add_test(NAME Cli.KilledRunsLeaveCoherentFolder
         COMMAND /usr/bin/python3 ${outputs_py}/check_output_kills.py ${cli} ${cli_out}/kills --trials 50)
set_tests_properties(Cli.KilledRunsLeaveCoherentFolder PROPERTIES TIMEOUT 400 PASS_REGULAR_EXPRESSION
                     "all 50 kills left a coherent folder")

# Test the full and the read-only file system on a tmpfs in a private mount namespace (skipped where no mount
# is allowed).
add_test(NAME Cli.FullDiskKeepsFolderCoherent
         COMMAND /usr/bin/python3 ${outputs_py}/check_output_mounts.py ${cli} ${cli_out}/mounts full)
set_tests_properties(Cli.FullDiskKeepsFolderCoherent PROPERTIES TIMEOUT 180 SKIP_RETURN_CODE 77
                     PASS_REGULAR_EXPRESSION "seeded results.json is kept byte for byte\nok")
add_test(NAME Cli.ReadOnlyFileSystemExits1
         COMMAND /usr/bin/python3 ${outputs_py}/check_output_mounts.py ${cli} ${cli_out}/mounts readonly)
set_tests_properties(Cli.ReadOnlyFileSystemExits1 PROPERTIES TIMEOUT 60 SKIP_RETURN_CODE 77
                     PASS_REGULAR_EXPRESSION "Read-only file system\nok")

# Test that a dump of fewer steps into a dump's folder removes the steps it does not rewrite, and that files and
# folders cloudbench did not write stay: notes.txt, and step_0003 (with mine.txt in it) minus the dump's files.
set(outputs_dump_script [=[d="$1"; rm -rf "$d"
"$0" dump ci-small --steps 5 --quiet --out "$d" >/dev/null || exit 9
echo note >"$d/notes.txt"; echo mine >"$d/step_0003/mine.txt"
"$0" dump ci-small --steps 2 --quiet --out "$d" >/dev/null || exit 9
cd "$d" && find . -path ./.cloudbench\* -prune -o -print | LC_ALL=C sort | tr '\n' ' ']=])
add_test(NAME Cli.DumpRemovesPreviousSteps COMMAND /bin/sh -c "${outputs_dump_script}" ${cli} ${cli_out}/redump)
set_tests_properties(Cli.DumpRemovesPreviousSteps PROPERTIES TIMEOUT 60 PASS_REGULAR_EXPRESSION
                     "notes\\.txt \\./step_0000 [^ ]* .*\\./step_0001 .*\\./step_0003 \\./step_0003/mine\\.txt"
                     FAIL_REGULAR_EXPRESSION "step_0002|step_0004|step_0003/[^m]")

# Test that no output follows a link (docs/results.md#output-folders): a link planted at each name a command
# creates, replaces, locks or removes (lock, journal, temporaries, results, frames, top view, step folders and
# their .npy files, conform, accuracy, sweep and shard outputs, merge outputs, the saved state, report -o and the
# perf writers) is refused with a message naming it, and the link's target is left byte for byte; a link the user
# names as the output folder, or in its path, is followed.
foreach(group run dump commands sweep named followed)
  add_test(NAME Cli.OutputLinks.${group}
           COMMAND /usr/bin/python3 ${outputs_py}/check_output_links.py ${cli} ${cli_out}/links ${group})
  set_tests_properties(Cli.OutputLinks.${group} PROPERTIES TIMEOUT 240 FAIL_REGULAR_EXPRESSION "FAIL: ")
endforeach()

# Test that the writers of perf compare --json, perf export, perf history --json, report -o, merge and sweep's
# plot say why they fail on a full and on a read-only file system, and that sweep exits 1 without a Python
# traceback when sweep.png does not fit.
foreach(kind full readonly)
  add_test(NAME Cli.Writers.${kind}DiskSaysWhy
           COMMAND /usr/bin/python3 ${outputs_py}/check_output_mounts.py ${cli} ${cli_out}/mounts writers-${kind})
  set_tests_properties(Cli.Writers.${kind}DiskSaysWhy PROPERTIES TIMEOUT 180 SKIP_RETURN_CODE 77
                       FAIL_REGULAR_EXPRESSION "FAIL: ")
endforeach()

# Test that a journal entry naming a folder (the journal lists only files) is left in place with a warning and
# does not stop the run, and that the next run, its journal rewritten, says nothing of it.
set(outputs_journal_folder_script [=[d="$1"; rm -rf "$d"; mkdir -p "$d/notes" || exit 9
echo mine >"$d/notes/mine.txt"; printf '= notes\n' >"$d/.cloudbench-run.files"
for n in 1 2; do
  "$0" run ci-small --backend cpu --steps 2 --set warmup_steps=0 --threads 2 --quiet --out "$d" \
    >/dev/null 2>"$d/../stderr-$n" || exit 8
done
cat "$d/../stderr-1"; echo "second run: $(wc -c <"$d/../stderr-2") bytes on stderr"; cat "$d/notes/mine.txt"]=])
add_test(NAME Cli.JournalNamingAFolderProceeds
         COMMAND /bin/sh -c "${outputs_journal_folder_script}" ${cli} ${cli_out}/journal-folder/out)
set_tests_properties(Cli.JournalNamingAFolderProceeds PROPERTIES TIMEOUT 60 PASS_REGULAR_EXPRESSION
                     "warning: [^\n]*/notes: a folder where the previous run wrote a file; left in place[^\n]*\n\
second run: 0 bytes on stderr\nmine\n")

# Test that tools/plot_sweep.py fails with one line and no traceback: a sweep.json it cannot read, one that is not
# JSON, and a plot it cannot write (into a folder that does not exist).
set(outputs_plot_script [=[d="$1"; rm -rf "$d"; mkdir -p "$d" && printf '{"rows": [' >"$d/cut.json" || exit 9
printf '%s' '{"scene": "s", "metric": "max", "vary": [{"path": "a", "values": ["1"]}], "rows": [{"status": "ok",
 "stage": "shade", "backend": "cpu", "time": {"median_ms": 1, "q1_ms": 1, "q3_ms": 1}, "error": {"all": {"max": 0.1}},
 "settings": {"a": "1"}, "pareto": true}]}' >"$d/one.json"
for args in "$d/missing.json $d/p.png" "$d/cut.json $d/p.png" "$d/one.json $d/none/p.png"; do
  /usr/bin/python3 "$0" $args 2>"$d/err"; echo "exit $? lines $(wc -l <"$d/err")"; cat "$d/err"
done]=])
add_test(NAME Cli.PlotSweepFailsInOneLine
         COMMAND /bin/sh -c "${outputs_plot_script}" ${CMAKE_SOURCE_DIR}/tools/plot_sweep.py ${cli_out}/plot-sweep)
set_tests_properties(Cli.PlotSweepFailsInOneLine PROPERTIES TIMEOUT 60 FAIL_REGULAR_EXPRESSION "Traceback"
                     PASS_REGULAR_EXPRESSION "^exit 1 lines 1\nplot_sweep.py: [^\n]*/missing.json: cannot read: \
No such file or directory\nexit 1 lines 1\nplot_sweep.py: [^\n]*/cut.json: not JSON: [^\n]*\nexit 1 lines 1\n\
plot_sweep.py: [^\n]*/none/p.png: cannot write: No such file or directory\n$")

# Test every reader and writer of every command (scenes, results folders and the frames they list, histories,
# suites, baselines, shards, kept interleaves, saved states; report -o, --json, --history, runs.log, run --out)
# against a link out of its folder, a link inside it, a FIFO, a folder, /dev/zero, an empty file and a file too
# large: the verdict, the exit code and the message the path policy gives (core/base/PathPolicy.h), and that
# nothing of a file outside reaches an output.
add_test(NAME Cli.PathPolicy COMMAND /usr/bin/python3 ${outputs_py}/check_path_policy.py ${cli} ${cli_out}/path-policy)
set_tests_properties(Cli.PathPolicy PROPERTIES TIMEOUT 400 FAIL_REGULAR_EXPRESSION "FAIL: "
                     PASS_REGULAR_EXPRESSION "every reader and writer follows the path policy")

# Test that a planted failed write, rename and remove (CLOUDBENCH_TEST_FAIL_FS) of each file run places (results.json,
# the frame's .exr and .png, the top view) exits 1 naming the file, never lists a file not placed (results.json, the
# journal), and frees the lock.
add_test(NAME Cli.FailedWritesKeepBookkeeping
         COMMAND /usr/bin/python3 ${outputs_py}/check_output_faults.py ${cli} ${cli_out}/faults)
set_tests_properties(Cli.FailedWritesKeepBookkeeping PROPERTIES TIMEOUT 120 PASS_REGULAR_EXPRESSION
                     "every planted failure left the bookkeeping true")
