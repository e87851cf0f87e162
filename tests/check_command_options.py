#!/usr/bin/python3
"""Each command's own options (harness/platform/Command.h, OwnOptions): every
own option of every command is parsed into that command's options, so a bad
value is refused with a usage message (exit 2) that names the option, and a
flag of its own is taken before a later bad option is refused; another
command's option is unknown there (exit 2). A wrongly typed option would end
the process with an uncaught std::bad_cast instead. Every numeric option, own,
shared or perf's, is refused outside its range with a message that states the
range enforced, the one docs/cli.md gives ("Numeric options").
Usage: check_command_options.py CLOUDBENCH"""
import subprocess
import sys

cli = sys.argv[1]

# (arguments, text the usage message must contain); each exits 2.
REFUSED = [
    (["run", "--timing", "bogus"], "--timing: must be synchronized, pipelined or both"),
    (["run", "--save-state"], "--save-state needs a folder"),
    (["run", "--resume", ""], "--resume: must not be empty"),
    (["run", "--save-state-every", "0"], "--save-state-every: needs a whole number in [1, 4294967295], got '0'"),
    (["run", "--save-state-every", "4294967296"], "--save-state-every: needs a whole number in [1, 4294967295]"),
    (["conform", "--baseline"], "--baseline needs a file of known failures"),
    (["conform", "--matrix", "--flake-reruns", "x"], "--flake-reruns: needs a whole number in [0, 100], got 'x'"),
    (["conform", "--flake-reruns", "101"], "--flake-reruns: needs a whole number in [0, 100], got '101'"),
    (["conform", "--flake-reruns", ""], "--flake-reruns: needs a whole number in [0, 100], got ''"),
    (["conform", "--vary"], "--vary needs PATH=V1,V2"),
    (["dump", "--reference", "--steps"], "--steps needs a number"),
    (["accuracy", "--switches", "--repeat", "0"], "--repeat: needs a whole number in [1, 10000], got '0'"),
    (["accuracy", "--repeat", "10001"], "--repeat: needs a whole number in [1, 10000], got '10001'"),
    (["accuracy", "--reference-step", "2"], "--reference-step: needs a number of voxel edges in [1/1024, 1], got '2'"),
    (["accuracy", "--reference-step"], "--reference-step: needs a number of voxel edges in [1/1024, 1]"),
    (["sweep", "--repeat"], "--repeat: needs a whole number in [1, 10000]"),
    (["sweep", "--reference-step", "0"], "--reference-step: needs a number of voxel edges in [1/1024, 1], got '0'"),
    (["sweep", "--metric", ""], "--metric: must not be empty"),
    (["sweep", "--vary"], "--vary needs PATH=V1,V2"),
    (["sweep", "--shard", "3/2"], "--shard needs I/N with 1 <= I <= N <= 1000000"),
    (["sweep", "--shard", "1/1000001"], "--shard needs I/N with 1 <= I <= N <= 1000000"),
    (["report", "-o"], "-o needs a file"),
    (["report", "--output", ""], "-o: must not be empty"),
    (["report", "--history"], "--history needs a file"),
    # The options every scene command shares: the bound a message states is the one enforced (docs/cli.md).
    (["run", "--threads", "1025"], "--threads: needs a whole number in [1, 1024], got '1025'"),
    (["run", "--threads", "+4"], "--threads: needs a whole number in [1, 1024], got '+4'"),
    (["run", "--backend-timeout", "10000001"], "--backend-timeout: needs seconds in [0, 10000000]"),
    # perf's numeric options: each refusal states the range, and a count takes no fraction.
    (["perf", "compare", "a", "b", "--threshold", "0.5"], "--threshold: needs a number in [1, 1000000], got '0.5'"),
    (["perf", "compare", "a", "b", "--separate-threshold", "2e6"], "--separate-threshold: needs a number in [1, 1000000]"),
    (["perf", "compare", "a", "b", "--floor", "-1"], "--floor: needs a number in [0, 1000000000], got '-1'"),
    (["perf", "compare", "a", "b", "--alpha", "0"], "--alpha: needs a number in [1e-12, 1], got '0'"),
    (["perf", "compare", "a", "b", "--instruction-threshold", "2e6"], "--instruction-threshold: needs a number in [0, 1000000]"),
    (["perf", "compare", "a", "b", "--run-quantile", "1.5"], "--run-quantile: needs a number in [0, 1], got '1.5'"),
    (["perf", "compare", "--interleave", "a", "b", "c", "--rounds", "1001"], "--rounds: needs a whole number in [1, 1000], got '1001'"),
    (["perf", "compare", "--interleave", "a", "b", "c", "--rounds", "2.5"], "--rounds: needs a whole number in [1, 1000], got '2.5'"),
    (["perf", "history", "h.jsonl", "--min-change", "101"], "--min-change: needs a number in [0, 100], got '101'"),
    (["perf", "history", "h.jsonl", "--min-segment", "1000001"], "--min-segment: needs a whole number in [1, 1000000], got '1000001'"),
    (["perf", "history", "h.jsonl", "--min-segment", "2.5"], "--min-segment: needs a whole number in [1, 1000000], got '2.5'"),
    (["perf", "record", "--repeat", "1001"], "--repeat: needs a whole number in [1, 1000], got '1001'"),
    # Another command's own option is not this one's.
    (["run", "--matrix"], "unknown option '--matrix'"),
    (["conform", "--timing", "pipelined"], "unknown option '--timing'"),
    (["dump", "--switches"], "unknown option '--switches'"),
    (["accuracy", "--reference"], "unknown option '--reference'"),
    (["report", "--metric", "max"], "unknown option '--metric'"),
]

failures = 0
for args, text in REFUSED:
    p = subprocess.run([cli] + args, capture_output=True, text=True, timeout=60)
    if p.returncode != 2 or text not in p.stderr:
        failures += 1
        print(f"FAIL: {' '.join(args)}: exit {p.returncode}, expected 2 and '{text}'\n{p.stderr}")
if failures:
    sys.exit(f"{failures} of {len(REFUSED)} command lines not refused as expected")
print(f"command options: ok ({len(REFUSED)} command lines)")
