#!/usr/bin/env python3
"""Runs the bad-input corpus (tests/bad_inputs/*.json) through a cloudbench CLI.

Each case file holds one input and its expected outcome:

  kind       group for the outcome table ("malformed JSON", "out of range", ...)
  about      one line: what the case is
  -- the input, one of --
  patch      {"dotted.path": value, ...} applied to the base scene (scenes/ci-small.json, cut to 3 steps);
             a value of null removes the field
  scene      a whole scene object
  text       the scene file's exact text (malformed JSON, control characters as \\u escapes)
  generate   {"what": "nested", "depth": N} | {"what": "huge_key", "bytes": N} | {"what": "fifo"} |
             {"what": "repeat", "before": TEXT, "unit": TEXT, "count": N, "after": TEXT}
  scene_path a path used as is (e.g. /dev/zero); no file is written
  args       a whole command line (after the program), for command-line cases; placeholders {scene} (the case's
             scene file, or scenes/ci-small.json when the case has none), {out} (a fresh output folder) and
             {repeat:C:N} (the character C N times)
  -- optional --
  file_name  the written scene's file name (default: the case's stem + ".json")
  commands   for scene cases, the commands run (default ["run", "dump"]), each as
             COMMAND {scene} --backend cpu --quiet --out {out}
  rlimit_as  RLIMIT_AS in bytes for the child (skipped with --skip-rlimit, e.g. under AddressSanitizer)
  timeout    seconds (default 60)
  -- expected --
  exit       the exit code
  message    a regex that stderr must contain ({scene} stands for the escaped scene path)

Every invocation must also: finish within its timeout, write no raw control byte to stderr (C0 other than
newline and tab, DEL, C1), write less than 64 KiB to stderr, and, when it exits 0, leave only finite numbers
in every .npy array and in results.json. A case passes when every command meets all of it.

Usage: check_bad_inputs.py --cli PATH [--filter RE] [--jobs N] [--skip-rlimit] [--write-scenes DIR]
Prints the outcome table and a summary; on failure, each failing invocation with its stderr.
Exit status 0 when every case passed.
"""
import argparse
import concurrent.futures
import copy
import json
import math
import os
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
CASES = HERE / "bad_inputs"
SCENES = HERE.parent / "scenes"
MAX_STDERR = 64 * 1024
# C0 controls except tab and newline, DEL, and C1 controls in their UTF-8 form (and raw, for non-UTF-8 output).
RAW_CONTROL = re.compile(rb"[\x00-\x08\x0b-\x1f\x7f]|\xc2[\x80-\x9f]")


def base_scene():
    scene = json.loads((SCENES / "ci-small.json").read_text())
    scene["steps"] = 3
    scene["warmup_steps"] = 1
    return scene


def apply_patch(scene, patch):
    for path, value in patch.items():
        keys = path.split(".")
        node = scene
        for key in keys[:-1]:
            node = node.setdefault(key, {})
        if value is None:
            node.pop(keys[-1], None)
        else:
            node[keys[-1]] = value
    return scene


def write_scene(case, folder):
    """The scene path for `case`, writing the file (or FIFO) under `folder`; None for command-line-only cases."""
    if "scene_path" in case:
        return case["scene_path"]
    path = folder / case.get("file_name", case["name"] + ".json")
    if "patch" in case:
        path.write_text(json.dumps(apply_patch(base_scene(), case["patch"]), indent=1))
    elif "scene" in case:
        path.write_text(json.dumps(case["scene"], indent=1))
    elif "text" in case:
        path.write_bytes(case["text"].encode("utf-8", "surrogateescape"))
    elif "generate" in case:
        what = case["generate"]["what"]
        if what == "nested":
            depth = case["generate"]["depth"]
            path.write_text('{"grid": ' + "[" * depth + "]" * depth + "}")
        elif what == "huge_key":
            key = "k" * case["generate"]["bytes"]
            path.write_text('{"grid": {"size": [8, 8, 8]}, "' + key + '": 1}')
        elif what == "repeat":
            g = case["generate"]
            path.write_text(g["before"] + g["unit"] * g["count"] + g["after"])
        elif what == "fifo":
            os.mkfifo(path)
        else:
            raise ValueError(f"{case['name']}: unknown generator {what}")
    else:
        return None
    return str(path)


def command_lines(case, scene):
    if "args" in case:
        return [case["args"]]
    return [[cmd, "{scene}", "--backend", "cpu", "--quiet", "--out", "{out}"] for cmd in case.get("commands",
                                                                                                  ["run", "dump"])]


def exr_floats(path):
    """Every pixel value of an OpenEXR file whose channels are all 32-bit floats, uncompressed or ZIP-compressed
    (what the harness writes), as one flat array; the layout does not matter for a finiteness check."""
    import numpy as np
    import zlib
    data = path.read_bytes()
    pos, attrs = 8, {}
    while data[pos] != 0:  # attributes: name\0 type\0 size value
        name_end = data.index(b"\0", pos)
        type_end = data.index(b"\0", name_end + 1)
        size = int.from_bytes(data[type_end + 1:type_end + 5], "little")
        attrs[data[pos:name_end].decode()] = data[type_end + 5:type_end + 5 + size]
        pos = type_end + 5 + size
    pos += 1
    channels = attrs["channels"]
    types, c = [], 0
    while channels[c] != 0:
        c = channels.index(b"\0", c) + 1
        types.append(int.from_bytes(channels[c:c + 4], "little"))
        c += 16
    compression = attrs["compression"][0]
    if set(types) != {2} or compression not in (0, 2, 3):
        raise ValueError(f"{path}: channel types {types}, compression {compression} not read here")
    x0, y0, x1, y1 = map(int, np.frombuffer(attrs["dataWindow"], "<i4"))
    lines_per_chunk = {0: 1, 2: 1, 3: 16}[compression]
    chunks = -(-(y1 - y0 + 1) // lines_per_chunk)
    offsets = np.frombuffer(data, "<u8", count=chunks, offset=pos)
    values = []
    for offset in map(int, offsets):
        size = int.from_bytes(data[offset + 4:offset + 8], "little")
        block = data[offset + 8:offset + 8 + size]
        y = int.from_bytes(data[offset:offset + 4], "little", signed=True)
        expected = 4 * len(types) * (x1 - x0 + 1) * min(lines_per_chunk, y1 + 1 - y)
        if size < expected:  # zlib, then the byte predictor and the split into two halves undone
            t = np.frombuffer(zlib.decompress(block), np.uint8).astype(np.int64)
            t = (np.cumsum(np.concatenate(([t[0]], t[1:] - 128))) & 0xFF).astype(np.uint8)
            half = (len(t) + 1) // 2
            raw = np.empty_like(t)
            raw[0::2], raw[1::2] = t[:half], t[half:]
            block = raw.tobytes()
        values.append(np.frombuffer(block, "<f4"))
    return np.concatenate(values)


def non_finite_in_outputs(out):
    """Names of output files under `out` that hold NaN or Inf (numpy arrays, EXR frames and JSON files)."""
    import numpy as np
    bad = []
    for npy in sorted(Path(out).rglob("*.npy")):
        a = np.load(npy)
        if a.dtype.kind == "f" and not np.isfinite(a).all():
            bad.append(f"{npy.relative_to(out)} ({int((~np.isfinite(a)).sum())} non-finite)")
    for exr in sorted(Path(out).rglob("*.exr")):
        a = exr_floats(exr)
        if not np.isfinite(a).all():
            bad.append(f"{exr.relative_to(out)} ({int((~np.isfinite(a)).sum())} non-finite)")
    for js in sorted(Path(out).rglob("*.json")):
        found = []

        def constant(token):
            found.append(token)
            return float(token.replace("Infinity", "inf"))

        try:
            json.loads(js.read_text(), parse_constant=constant)
        except ValueError as e:
            bad.append(f"{js.relative_to(out)} (not JSON: {e})")
        if found:
            bad.append(f"{js.relative_to(out)} ({', '.join(sorted(set(found)))})")
    return bad


def run_case(cli, case, skip_rlimit):
    """(outcome, problems, invocations) for one case; outcome is 'refused', 'finite' or 'failed'."""
    if skip_rlimit and "rlimit_as" in case:
        return "skipped", [], 0
    problems = []
    exits = []
    with tempfile.TemporaryDirectory(prefix="badinput-") as tmp:
        tmp = Path(tmp)
        scene = write_scene(case, tmp) or str(SCENES / "ci-small.json")
        lines = command_lines(case, scene)
        for n, line in enumerate(lines):
            out = tmp / f"out{n}"
            argv = [cli] + [re.sub(r"\{repeat:(.):(\d+)\}", lambda m: m[1] * int(m[2]),
                                   a.replace("{scene}", scene).replace("{out}", str(out))) for a in line]
            limit = case.get("rlimit_as")

            def preexec():
                if limit:
                    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))

            start = time.monotonic()
            timeout = case.get("timeout", 60)
            try:
                proc = subprocess.run(argv, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                      timeout=timeout, preexec_fn=preexec)
            except subprocess.TimeoutExpired:
                problems.append(f"{line[0]}: no exit within {timeout} s")
                continue
            seconds = time.monotonic() - start
            err = proc.stderr
            shown = " ".join(argv[1:])[:200]
            text = err[:4000].decode("utf-8", "backslashreplace")
            exits.append(proc.returncode)

            def fail(what):
                problems.append(f"{shown}\n      {what}\n      exit {proc.returncode}, {seconds:.1f} s, stderr: "
                                f"{text!r}")

            if proc.returncode != case["exit"]:
                fail(f"expected exit {case['exit']}")
            if len(err) >= MAX_STDERR:
                fail(f"stderr has {len(err)} bytes (limit {MAX_STDERR})")
            if m := RAW_CONTROL.search(err):
                fail(f"raw control byte {m.group(0)!r} in stderr")
            if "message" in case:
                pattern = case["message"].replace("{scene}", re.escape(scene))
                if not re.search(pattern, err.decode("utf-8", "replace"), re.MULTILINE):
                    fail(f"stderr does not match {pattern!r}")
            if proc.returncode == 0:
                if bad := non_finite_in_outputs(out):
                    fail("non-finite values: " + "; ".join(bad))
            shutil.rmtree(out, ignore_errors=True)
    if problems:
        return "failed", problems, len(lines)
    return ("finite" if exits and all(e == 0 for e in exits) else "refused"), [], len(lines)


def load_cases(filter_re):
    cases = []
    for path in sorted(CASES.glob("*.json")):
        case = json.loads(path.read_text())
        case["name"] = path.stem
        for key in ("kind", "about", "exit"):
            if key not in case:
                raise ValueError(f"{path}: missing '{key}'")
        if case["exit"] != 0 and "message" not in case:
            raise ValueError(f"{path}: a refusal needs a 'message'")
        if filter_re and not re.search(filter_re, case["name"]) and not re.search(filter_re, case["kind"]):
            continue
        cases.append(case)
    return cases


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--cli", required=True, help="the cloudbench executable")
    parser.add_argument("--filter", help="only cases whose name or kind matches this regex")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--skip-rlimit", action="store_true",
                        help="skip cases that set RLIMIT_AS (AddressSanitizer reserves more address space)")
    parser.add_argument("--write-scenes", metavar="DIR",
                        help="only write each case's scene file into DIR (e.g. to seed a fuzzer), run nothing")
    args = parser.parse_args()
    cases = load_cases(args.filter)
    if not cases:
        print("no case matches", file=sys.stderr)
        return 1

    if args.write_scenes:
        folder = Path(args.write_scenes)
        folder.mkdir(parents=True, exist_ok=True)
        written = 0
        for case in cases:
            if any(k in case for k in ("patch", "scene", "text")) or case.get("generate", {}).get("what") == "repeat":
                write_scene(dict(case, file_name=case["name"] + ".json"), folder)
                written += 1
        print(f"{written} scene files written to {folder}")
        return 0

    cli = str(Path(args.cli).resolve())
    results = {}
    with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        futures = {pool.submit(run_case, cli, case, args.skip_rlimit): case["name"] for case in cases}
        for future in concurrent.futures.as_completed(futures):
            results[futures[future]] = future.result()

    by_kind = {}
    invocations = 0
    for case in cases:
        outcome, _, count = results[case["name"]]
        invocations += count
        row = by_kind.setdefault(case["kind"], {"refused": 0, "finite": 0, "failed": 0, "skipped": 0})
        row[outcome] += 1
    width = max(len(k) for k in by_kind)
    print(f"{'kind':<{width}}  refused  finite  failed  skipped")
    for kind, row in sorted(by_kind.items()):
        print(f"{kind:<{width}}  {row['refused']:7}  {row['finite']:6}  {row['failed']:6}  {row['skipped']:7}")
    totals = {k: sum(r[k] for r in by_kind.values()) for k in ("refused", "finite", "failed", "skipped")}
    print(f"{len(cases)} cases, {invocations} invocations: {totals['refused']} refused clearly, "
          f"{totals['finite']} computed finite, {totals['failed']} failed, {totals['skipped']} skipped")
    for case in cases:
        outcome, problems, _ = results[case["name"]]
        if problems:
            print(f"\nFAILED {case['name']} ({case['kind']}): {case['about']}")
            for p in problems:
                print("  - " + p)
    return 1 if totals["failed"] else 0


if __name__ == "__main__":
    sys.exit(main())
