#!/usr/bin/env bash
# Dumps ci-small on one backend and checks the dump with check_dump.py (the
# NumPy re-implementation). Exits 4, a CTest skip, when the backend cannot start.
# Usage: dump_and_check.sh CLOUDBENCH BACKEND OUT_DIR CHECK_DUMP_PY SCENE_JSON
set -u
cli=$1 backend=$2 out=$3 check=$4 scene=$5
"$cli" dump ci-small --backend "$backend" --steps 3 --quiet --out "$out"
rc=$?
[ $rc -eq 4 ] && { echo "skipped: backend $backend is unavailable here"; exit 4; }
[ $rc -eq 0 ] || { echo "dump failed with exit code $rc"; exit 1; }
/usr/bin/python3 "$check" "$out" 3 "$scene"
