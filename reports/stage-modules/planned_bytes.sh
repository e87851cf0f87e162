#!/bin/bash
# usage: planned_bytes.sh /ABS/PATH/cloudbench /ABS/OUTFILE -- planned_bytes (results.json) of
# scenes x variants x backends, one line each: scene, variant, backend, bytes.
BIN=$1; OUT=$2; : > $OUT
cd "$(dirname "$0")/../.."
one() { # scene variant...
  local s=$1; shift; local n=$(basename $s .json); local d=${TMPDIR:-/tmp}/planned-$n; rm -rf $d
  timeout 600 $BIN run $s --steps 2 --set warmup_steps=1 --quiet --out $d "$@" > /dev/null 2>&1
  /usr/bin/python3 -c "
import json,sys
r=json.load(open('$d/results.json'))
for k,b in sorted(r['backends'].items()):
    print('$n', '$*'.replace(' ','_') or '-', k, b.get('planned_bytes'))
" >> $OUT 2>/dev/null || echo "$n $* FAILED" >> $OUT
}
for s in ci-small ci-small-wind ground-shadow lightning noise-layer thesis-low thesis-sunset; do one scenes/$s.json; done
for s in ci-small ci-small-wind ground-shadow lightning; do
  one scenes/$s.json --set shade.resolution=2
  one scenes/$s.json --set shade.resolution=4 --set smooth.radius=2
  one scenes/$s.json --gl-ca-layout rgba8 --threads 1
  one scenes/$s.json --set render.slices_per_frame=4 --set smooth.radius=1
done
one scenes/ci-small-wind.json --gl-ca-layout rgba8 --set shade.resolution=2
one scenes/ci-small.json --set ca.wind_shift=[[1,0]] --gl-ca-layout rgba8
one scenes/ci-small.json --set ca.wind_shift=[[1,0]]
