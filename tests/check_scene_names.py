#!/usr/bin/python3
"""A SCENE argument that names no scene (docs/cli.md, "Exit codes").

usage: check_scene_names.py CLOUDBENCH SCENES_DIR OUT
  SCENES_DIR is the scenes folder compiled into CLOUDBENCH, spelled as the build spells it.

Every command that takes a scene answers a mistyped name ("wang20km") with exit 3 and one line on stderr that
names the file it looked for, lists the scenes of the folder (read here from SCENES_DIR itself) and suggests the
one a character away, and writes nothing. A name close to none gets no suggestion; CLOUDBENCH_SCENES moves the
folder the names come from; a path that does not exist is named as the path. Prints "scene names: ok".
"""
import os
import shutil
import subprocess
import sys

# Each command that takes a SCENE, with the options it needs to get as far as loading one.
COMMANDS = [
    ["run"],
    ["conform"],
    ["dump"],
    ["accuracy"],
    ["sweep", "--vary", "shade.resolution=1,2"],
    ["count"],
]


def fail(message):
    print("FAIL: " + message)
    sys.exit(1)


def scene_names(folder):
    return sorted(f[:-5] for f in os.listdir(folder) if f.endswith(".json") and len(f) > 5)


def run(cli, args, cwd, env=None):
    """The CLI with CLOUDBENCH_SCENES only as `env` sets it (without it, the folder compiled in: SCENES_DIR)."""
    base = {k: v for k, v in os.environ.items() if k != "CLOUDBENCH_SCENES"}
    return subprocess.run([cli] + args, capture_output=True, text=True, cwd=cwd, timeout=60, env=dict(base, **(env or {})))


def expect(result, args, code, stderr):
    what = " ".join(args)
    if result.returncode != code:
        fail(f"{what}: exit {result.returncode}, expected {code}; stderr: {result.stderr!r}")
    if result.stderr != stderr + "\n":
        fail(f"{what}: stderr\n  {result.stderr!r}\nexpected\n  {stderr + chr(10)!r}")


def unknown(folder, name, suggestion):
    listed = ", ".join(scene_names(folder))
    message = f"cloudbench: SCENE: no scene named '{name}' (no file {folder}/{name}.json); the scenes there: {listed}"
    return message + (f"; did you mean '{suggestion}'?" if suggestion else "")


def main():
    cli, scenes, out = sys.argv[1], os.path.normpath(sys.argv[2]), sys.argv[3]
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(out)
    # The case below depends on these two: "wang20km" is one edit from wang-20km and two from wang-90km.
    if not {"wang-20km", "wang-90km"} <= set(scene_names(scenes)):
        fail(f"{scenes} lacks wang-20km or wang-90km")
    env = {}

    # A mistyped name, in every command: the list, the nearest, exit 3, nothing written.
    for command in COMMANDS:
        args = [command[0], "wang20km"] + command[1:] + ["--out", os.path.join(out, command[0])]
        expect(run(cli, args, out, env), args, 3, unknown(scenes, "wang20km", "wang-20km"))
        if os.path.exists(os.path.join(out, command[0])):
            fail(" ".join(args) + ": wrote its output folder")
    # Two close names, the nearer suggested; a name close to none, no suggestion.
    for name, suggestion in [("thesis-mdium", "thesis-medium"), ("zzzzzzzz", None)]:
        args = ["run", name, "--out", os.path.join(out, "run")]
        expect(run(cli, args, out, env), args, 3, unknown(scenes, name, suggestion))

    # CLOUDBENCH_SCENES: the names and the list come from that folder; a file that is not a scene is not listed.
    mine = os.path.join(out, "my-scenes")
    os.makedirs(mine)
    for name in ["alpha", "beta"]:
        shutil.copy(os.path.join(scenes, "ci-small.json"), os.path.join(mine, name + ".json"))
    with open(os.path.join(mine, "notes.txt"), "w") as notes:
        notes.write("not a scene\n")
    args = ["run", "alpah", "--out", os.path.join(out, "run")]
    expect(run(cli, args, out, {"CLOUDBENCH_SCENES": mine}), args, 3,
           f"cloudbench: SCENE: no scene named 'alpah' (no file {mine}/alpah.json); the scenes there: alpha, beta;"
           " did you mean 'alpha'?")
    # A name that is there is loaded from there: the loader's own error names that file.
    args = ["run", "alpha", "--set", "ca.p_ext=2", "--out", os.path.join(out, "run")]
    result = run(cli, args, out, {"CLOUDBENCH_SCENES": mine})
    if result.returncode != 3 or not result.stderr.startswith(f"{mine}/alpha.json: ca.p_ext: "):
        fail(f"run alpha from {mine}: exit {result.returncode}, stderr {result.stderr!r}")
    empty = os.path.join(out, "no-scenes")
    os.makedirs(empty)
    args = ["run", "alpha", "--out", os.path.join(out, "run")]
    expect(run(cli, args, out, {"CLOUDBENCH_SCENES": empty}), args, 3,
           f"cloudbench: SCENE: no scene named 'alpha' (no file {empty}/alpha.json); {empty} holds no scene (*.json)")
    absent = os.path.join(out, "absent")
    result = run(cli, args, out, {"CLOUDBENCH_SCENES": absent})
    prefix = f"cloudbench: SCENE: no scene named 'alpha' (no file {absent}/alpha.json); {absent}: cannot list the folder: "
    if result.returncode != 3 or not result.stderr.startswith(prefix):
        fail(f"run alpha from a missing folder: exit {result.returncode}, stderr {result.stderr!r}")

    # A path that does not exist is named as given, relative or not.
    for path in ["wang20km.json", os.path.join(out, "nowhere", "wang20km.json")]:
        args = ["run", path, "--out", os.path.join(out, "run")]
        expect(run(cli, args, out, env), args, 3, f"{path}: cannot read the file: No such file or directory")
    if os.path.exists(os.path.join(out, "run")):
        fail("a refused scene wrote the output folder")
    print("scene names: ok")


if __name__ == "__main__":
    main()
