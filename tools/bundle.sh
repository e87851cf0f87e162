#!/usr/bin/env bash
# Packs an installed cloudbench and every shared library it loads into one folder, for a Linux x86-64 machine
# that has a GPU driver but not the build's Debian packages (a container, a cluster node, a lent GPU host):
#   bin/cloudbench (and bin/cloudbench_tests when the build has it), lib/cloudbench/ (the image module),
#   share/cloudbench/ (scenes, scripts), lib/deps/ (every library ldd lists for them except the C runtime's),
#   and env.sh, which puts lib/deps on the library path and points the Vulkan loader and glvnd's EGL at the
#   host's NVIDIA driver files where it finds them (other drivers are found by the loader's own search).
# The build is portable (baseline x86-64), so the bundle runs on any x86-64 CPU. Usage:
#   tools/bundle.sh [BUILD_DIR] [OUT_DIR]        (defaults: build/release, bundle)
# On the host:  . OUT_DIR/env.sh && cloudbench devices && cloudbench conform ci-small --gl-context egl
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build/release}
out=${2:-$root/bundle}
[ -x "$build/cloudbench" ] || { echo "bundle: no $build/cloudbench; build the release preset first" >&2; exit 1; }
rm -rf "$out"
cmake --install "$build" --prefix "$out" >/dev/null
tests=$(find "$build/tests" -maxdepth 1 -name cloudbench_tests -type f -perm -u+x 2>/dev/null | head -n 1)
[ -n "$tests" ] && cp "$tests" "$out/bin/"
mkdir -p "$out/lib/deps"
# The C runtime stays the host's (it must match its dynamic loader); everything else ldd resolves is copied.
for binary in "$out"/bin/* "$out"/lib/cloudbench/*.so; do
  ldd "$binary" | awk '$2 == "=>" && $3 ~ /^\// {print $3}'
done | sort -u | grep -v -E '/(libc|libm|libpthread|libdl|librt|libresolv|ld-linux-x86-64)\.so' |
  while read -r library; do cp -L "$library" "$out/lib/deps/"; done
cat >"$out/env.sh" <<'ENV'
# Source on the host: . BUNDLE/env.sh
b=$(cd "$(dirname "${BASH_SOURCE[0]:-$0}")" && pwd)
export PATH=$b/bin:$PATH
export LD_LIBRARY_PATH=$b/lib/deps:/usr/local/nvidia/lib64:/usr/local/nvidia/lib:${LD_LIBRARY_PATH:-}
for f in /usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json /etc/vulkan/icd.d/nvidia_icd.json \
         /usr/share/vulkan/icd.d/nvidia_icd.json; do
  [ -f "$f" ] && { export VK_DRIVER_FILES=$f VK_ICD_FILENAMES=$f; break; }; done
for f in /usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json /usr/share/glvnd/egl_vendor.d/10_nvidia.json; do
  [ -f "$f" ] && { export __EGL_VENDOR_LIBRARY_FILENAMES=$f; break; }; done
true
ENV
# Every library the binaries need must now resolve inside the bundle or the host's C runtime.
missing=$(for binary in "$out"/bin/* "$out"/lib/cloudbench/*.so; do
  LD_LIBRARY_PATH=$out/lib/deps ldd "$binary" | grep "not found" || true; done)
[ -z "$missing" ] || { echo "bundle: unresolved libraries: $missing" >&2; exit 1; }
echo "bundle: $(du -sh "$out" | cut -f1) in $out; on the host: . $out/env.sh && cloudbench devices"
