#!/usr/bin/python3
"""The installed cloudbench runs with the source and build trees gone.

Usage: check_install.py BUILD_DIR SOURCE_DIR OUT_DIR

Installs BUILD_DIR with `cmake --install` into a staging folder (DESTDIR, prefix /usr, as the .deb lays it
out); builds the .deb with CPack and checks that it holds the same files and declares the shared libraries the
binary needs as dependencies; copies the staged /usr to a folder of its own (the copy alone is used, so the install is relocatable),
and from there, with SOURCE_DIR hidden under an empty tmpfs in a private mount namespace where the system
allows one (`unshare`; otherwise the source tree stays visible and the test says so):
  - `--version` names the version, the commit and the build type, and reads its scenes and image module from
    the copy;
  - `run ci-small` (by name, found in the copy's scenes) writes results.json, whose provenance names the
    copy's scene file and the same version, and PNG frames (the image module loads);
  - a scene given by path still works;
  - `conform ci-small` and `report` on the run's folder succeed.
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile

build, source, out = sys.argv[1:4]


def fail(message, proc=None):
    if proc is not None:
        message += "\n--- stdout\n%s\n--- stderr\n%s" % (proc.stdout, proc.stderr)
    sys.exit("install: " + message)


shutil.rmtree(out, ignore_errors=True)
os.makedirs(out)
stage = os.path.join(out, "stage")
env = dict(os.environ, DESTDIR=stage)
p = subprocess.run(["cmake", "--install", build, "--prefix", "/usr"], env=env, capture_output=True, text=True)
if p.returncode != 0:
    fail("cmake --install failed", p)
staged = sorted(os.path.relpath(os.path.join(d, n), stage) for d, _, names in os.walk(stage) for n in names)

# The package: the same files under /usr, and a dependency on each library package the binary links.
p = subprocess.run(["cpack", "-G", "DEB", "-B", os.path.join(out, "deb"), "--config",
                    os.path.join(build, "CPackConfig.cmake")], capture_output=True, text=True)
if p.returncode != 0:
    fail("cpack -G DEB failed", p)
debs = [n for n in os.listdir(os.path.join(out, "deb")) if n.endswith(".deb")]
if len(debs) != 1:
    fail("cpack made %s, not one .deb" % debs)
deb = os.path.join(out, "deb", debs[0])
listing = subprocess.run(["dpkg-deb", "-c", deb], capture_output=True, text=True, check=True).stdout
packaged = sorted(line.split()[-1].lstrip("./") for line in listing.splitlines() if not line.startswith("d"))
if packaged != staged:
    fail("the .deb's files differ from cmake --install's: %s" % sorted(set(packaged) ^ set(staged)))
depends = subprocess.run(["dpkg-deb", "-f", deb, "Depends"], capture_output=True, text=True, check=True).stdout
for library in ("libtbb12", "libhwy1", "libopenimageio", "libvulkan1", "libembree3", "libosmesa6", "libegl1"):
    if library not in depends:
        fail("the .deb does not depend on %s: Depends: %s" % (library, depends))

# Outside the source tree (the build folder, and so OUT_DIR, may lie inside it, and it is hidden below).
outside = tempfile.mkdtemp(prefix="cloudbench-install-")
prefix = os.path.join(outside, "usr")
shutil.copytree(os.path.join(stage, "usr"), prefix, dirs_exist_ok=True)
shutil.rmtree(stage)
cli = os.path.join(prefix, "bin", "cloudbench")
for path in [cli, os.path.join(prefix, "lib/cloudbench/libcloudbench_images.so"),
             os.path.join(prefix, "share/cloudbench/scenes/ci-small.json"),
             os.path.join(prefix, "share/cloudbench/tools/plot_sweep.py"),
             os.path.join(prefix, "share/doc/cloudbench/README.md")]:
    if not os.path.exists(path):
        fail("not installed: " + os.path.relpath(path, prefix))

hidden = subprocess.run(["unshare", "--map-root-user", "--mount", "true"], capture_output=True).returncode == 0
if not hidden:
    print("install: note: no private mount namespace here (unshare); the source tree stays visible")
work = os.path.join(outside, "work")
os.makedirs(work)
script = os.path.join(outside, "steps.sh")
with open(script, "w") as f:
    f.write("""set -e
if [ "$HIDE" = 1 ]; then mount -t tmpfs none "$SOURCE"; test -z "$(ls -A "$SOURCE")"; fi
cd "$WORK"
"$CLI" --version > version.txt
"$CLI" run ci-small --backend cpu --steps 3 --set warmup_steps=0 --quiet --out by-name
cp "$PREFIX/share/cloudbench/scenes/ci-small.json" own.json
"$CLI" run ./own.json --backend cpu --steps 2 --set warmup_steps=0 --quiet --out by-path
"$CLI" conform ci-small --steps 2 --quiet --out conform > conform.txt
"$CLI" report by-name -o report.html > /dev/null
""")
run_env = dict(os.environ, HIDE="1" if hidden else "0", SOURCE=os.path.abspath(source), WORK=work, CLI=cli,
               PREFIX=prefix)
run_env.pop("CLOUDBENCH_SCENES", None)
command = ["/bin/sh", script]
if hidden:
    command = ["unshare", "--map-root-user", "--mount"] + command
p = subprocess.run(command, env=run_env, capture_output=True, text=True, timeout=600)
if p.returncode != 0:
    fail("a command of the installed binary failed (exit %d)" % p.returncode, p)

version = open(os.path.join(work, "version.txt")).read()
lines = {}
for line in version.splitlines():
    for key in ("cloudbench", "commit", "build", "scenes", "image module"):
        if line.startswith(key + " "):
            lines[key] = line[len(key) + 1:]
if not lines.get("cloudbench", "").strip() or not lines.get("commit") or not lines.get("build", "").startswith(
        ("Release", "RelWithDebInfo", "Debug", "MinSizeRel")):
    fail("--version: " + version)
if lines.get("scenes") != os.path.join(prefix, "share/cloudbench/scenes"):
    fail("--version: scenes not read from the install: " + version)
if lines.get("image module") != os.path.join(prefix, "lib/cloudbench/libcloudbench_images.so"):
    fail("--version: the image module is not the installed one: " + version)
with open(os.path.join(work, "by-name", "results.json")) as f:
    provenance = json.load(f)["provenance"]
if provenance["scene"]["path"] != os.path.join(prefix, "share/cloudbench/scenes/ci-small.json"):
    fail("the scene was not found in the install: " + provenance["scene"]["path"])
if provenance["build"]["version"] != lines["cloudbench"]:
    fail("provenance's version %s differs from --version's %s" % (provenance["build"]["version"], lines["cloudbench"]))
if not any(n.endswith(".png") for n in os.listdir(os.path.join(work, "by-name"))):
    fail("no PNG frame: the image module did not load")
with open(os.path.join(work, "by-path", "results.json")) as f:
    if not json.load(f)["provenance"]["scene"]["path"].endswith("own.json"):
        fail("a scene given by path was not used")
if not os.path.getsize(os.path.join(work, "report.html")):
    fail("report wrote nothing")
shutil.rmtree(outside)
print("install: ok (%s)" % ("source tree hidden" if hidden else "source tree visible"))
