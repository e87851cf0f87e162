#!/usr/bin/python3
"""Each command's own options (harness/platform/Command.h, OwnOptions): every
own option of every command is parsed into that command's options, so a bad
value is refused with a usage message (exit 2) that names the option, and a
flag of its own is taken before a later bad option is refused; another
command's option is unknown there (exit 2). A wrongly typed option would end
the process with an uncaught std::bad_cast instead.
Usage: check_command_options.py CLOUDBENCH"""
import subprocess
import sys

cli = sys.argv[1]

# (arguments, text the usage message must contain); each exits 2.
REFUSED = [
    (["run", "--timing", "bogus"], "--timing: must be synchronized, pipelined or both"),
    (["run", "--save-state"], "--save-state needs a folder"),
    (["run", "--resume", ""], "--resume: must not be empty"),
    (["run", "--save-state-every", "0"], "--save-state-every needs a step count > 0"),
    (["conform", "--baseline"], "--baseline needs a file of known failures"),
    (["conform", "--matrix", "--flake-reruns", "x"], "--flake-reruns needs a count from 0 to 100"),
    (["conform", "--vary"], "--vary needs PATH=V1,V2"),
    (["dump", "--reference", "--steps"], "--steps needs a number"),
    (["accuracy", "--switches", "--repeat", "0"], "--repeat needs a number from 1"),
    (["accuracy", "--reference-step", "2"], "--reference-step needs a number of voxel edges"),
    (["accuracy", "--reference-step"], "--reference-step needs a number of voxel edges"),
    (["sweep", "--repeat"], "--repeat needs a number from 1"),
    (["sweep", "--reference-step", "0"], "--reference-step needs a number of voxel edges"),
    (["sweep", "--metric", ""], "--metric: must not be empty"),
    (["sweep", "--vary"], "--vary needs PATH=V1,V2"),
    (["sweep", "--shard", "3/2"], "--shard needs I/N with 1 <= I <= N"),
    (["report", "-o"], "-o needs a file"),
    (["report", "--output", ""], "-o: must not be empty"),
    (["report", "--history"], "--history needs a file"),
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
