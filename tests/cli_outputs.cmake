# Coherent output folders (issue 11; docs/results.md#output-folders): one command per folder at a time (a lock),
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
