#!/usr/bin/env bash
# Installs Debian 12 packages with apt-get.
#   tools/setup.sh        everything: tools/debian-packages-run.txt and tools/debian-packages.txt
#   tools/setup.sh run    only what building the CLI and `cloudbench run` need (debian-packages-run.txt)
# Safe to run again: when every package is already installed it does nothing
# (and needs neither root nor the network). As a non-root user it uses sudo if
# there is one; otherwise it prints the apt-get line to run as root and fails.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
lists=("$here/debian-packages-run.txt")
case "${1:-all}" in
  run) ;;
  all) lists+=("$here/debian-packages.txt") ;;
  *) echo "setup: unknown argument '$1'; use 'run' (what cloudbench run needs) or nothing (everything)" >&2; exit 2 ;;
esac
mapfile -t packages < <(cat "${lists[@]}" | grep -v '^\s*#' | grep -v '^\s*$')

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages are installed"
  exit 0
fi

echo "setup: installing ${missing[*]}"
if [ "$(id -u)" -eq 0 ]; then
  sudo=()
elif command -v sudo >/dev/null 2>&1; then
  sudo=(sudo)
else
  echo "setup: not root and no sudo; as root, run:" >&2
  echo "  apt-get update && apt-get install -y --no-install-recommends ${missing[*]}" >&2
  exit 1
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo[@]}" apt-get update -q
"${sudo[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
