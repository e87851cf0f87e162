# render_march through the CLI. Included from tests/CMakeLists.txt where `cli` and `cli_out` are set.
# ci-small with the ray marcher: `run` writes the EXR and the tone-mapped PNG and the march counters; skipping
# on and off write the same EXR pixels (skipping changes no sample, docs/pipeline.md) with fewer samples.
set(cli_march_script [=[d="$1"; rm -rf "$d"; set -e
st='stages=["region","ca","smooth","density","shade","render_march"]'
"$0" run ci-small --backend cpu --quiet --out "$d/on" --set "$st" --set steps=12 --set warmup_steps=10 >/dev/null
"$0" run ci-small --backend cpu --quiet --out "$d/off" --set "$st" --set steps=12 --set warmup_steps=10 \
  --set march.skipping.enabled=false >/dev/null
test -s "$d/on/frame-march-above-cpu.png" && test -s "$d/on/frame-march-above-cpu.exr"
/usr/bin/python3 - "$d" "$2" <<'PY'
import json, pathlib, sys
sys.path.insert(0, sys.argv[2])
from check_bad_inputs import exr_floats  # the pixels, not the header (which holds a time stamp)
a, b = (exr_floats(pathlib.Path(sys.argv[1]) / k / "frame-march-above-cpu.exr") for k in ("on", "off"))
assert a.size == 160 * 120 * 3 and (a == b).all(), "the images differ"
print("same image")
def frames(name):
    r = json.load(open(sys.argv[1] + "/" + name + "/results.json"))
    return r["backends"]["cpu"]["march_frames"]["above"]
on, off = frames("on"), frames("off")
assert on["samples"][-1] < off["samples"][-1], (on["samples"], off["samples"])
assert on["light_samples"] == off["light_samples"], (on["light_samples"], off["light_samples"])
assert on["bricks_skipped"][-1] > 0 and off["bricks_skipped"][-1] == 0
print("fewer samples")
PY]=])
add_test(NAME Cli.MarchRunSkippingSameImage COMMAND /bin/sh -c "${cli_march_script}" ${cli} ${cli_out}/march
         ${CMAKE_CURRENT_SOURCE_DIR})
set_tests_properties(Cli.MarchRunSkippingSameImage PROPERTIES TIMEOUT 120 PASS_REGULAR_EXPRESSION
                     "same image\nfewer samples")
