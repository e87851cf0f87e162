#!/usr/bin/python3
"""tools/bundle.sh makes a folder that runs with nothing of the build's packages but the C runtime.

Usage: check_bundle.py BUILD_DIR SOURCE_DIR OUT_DIR

Bundles BUILD_DIR into OUT_DIR/bundle, then checks with ldd, under the bundle's env.sh, that every library the
binary and the image module load (but the C runtime's) resolves inside the bundle, and, with SOURCE_DIR hidden
under an empty tmpfs where a private mount namespace is allowed, runs the bundled `cloudbench run ci-small` by
name and writes its PNG frames.
"""
import os
import re
import shutil
import subprocess
import sys
import tempfile

build, source, out = sys.argv[1:4]
C_RUNTIME = re.compile(r"/(libc|libm|libpthread|libdl|librt|libresolv|ld-linux-x86-64)\.so")


def fail(message, proc=None):
    if proc is not None:
        message += "\n--- stdout\n%s\n--- stderr\n%s" % (proc.stdout[-4000:], proc.stderr[-4000:])
    sys.exit("bundle: " + message)


shutil.rmtree(out, ignore_errors=True)
os.makedirs(out)
# Outside the source tree (the build folder, and so OUT_DIR, may lie inside it, and it is hidden below).
outside = tempfile.mkdtemp(prefix="cloudbench-bundle-")
bundle = os.path.join(outside, "bundle")
p = subprocess.run([os.path.join(source, "tools", "bundle.sh"), build, bundle], capture_output=True, text=True)
if p.returncode != 0:
    fail("tools/bundle.sh failed", p)
env_sh = os.path.join(bundle, "env.sh")
deps = os.path.join(bundle, "lib", "deps")
for binary in (os.path.join(bundle, "bin", "cloudbench"),
               os.path.join(bundle, "lib", "cloudbench", "libcloudbench_images.so")):
    p = subprocess.run(["/bin/bash", "-c", '. "$1" && ldd "$2"', "-", env_sh, binary], capture_output=True, text=True)
    if p.returncode != 0:
        fail("ldd " + binary, p)
    for line in p.stdout.splitlines():
        parts = line.split()
        if len(parts) >= 3 and parts[1] == "=>":
            path = parts[2]
            if path == "not":
                fail("%s: %s is not found" % (binary, parts[0]))
            if not C_RUNTIME.search(path) and not path.startswith(deps + "/"):
                fail("%s loads %s from outside the bundle" % (binary, path))

hidden = subprocess.run(["unshare", "--map-root-user", "--mount", "true"], capture_output=True).returncode == 0
work = os.path.join(outside, "work")
os.makedirs(work)
script = ('set -e\nif [ "$HIDE" = 1 ]; then mount -t tmpfs none "$SOURCE"; fi\n. "$ENV_SH"\ncd "$WORK"\n'
          'cloudbench run ci-small --backend cpu --steps 2 --set warmup_steps=0 --quiet --out run\n')
command = ["/bin/bash", "-c", script]
if hidden:
    command = ["unshare", "--map-root-user", "--mount"] + command
env = dict(os.environ, HIDE="1" if hidden else "0", SOURCE=os.path.abspath(source), ENV_SH=env_sh, WORK=work)
env.pop("CLOUDBENCH_SCENES", None)
p = subprocess.run(command, env=env, capture_output=True, text=True, timeout=300)
if p.returncode != 0:
    fail("the bundled cloudbench failed", p)
if not any(n.endswith(".png") for n in os.listdir(os.path.join(work, "run"))):
    fail("the bundled cloudbench wrote no PNG frame")
shutil.rmtree(outside)  # about half a gigabyte: OpenImageIO's libraries
print("bundle: ok (%s)" % ("source tree hidden" if hidden else "source tree visible"))
