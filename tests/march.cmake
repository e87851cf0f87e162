# render_march through the CLI (issue 13). Included from tests/CMakeLists.txt where `cli` and `cli_out` are set.
# ci-small with the ray marcher: `run` writes the EXR and the tone-mapped PNG and the march counters; skipping
# on and off write the same EXR byte for byte (skipping changes no sample, docs/pipeline.md) with fewer samples.
set(cli_march_script [=[d="$1"; rm -rf "$d"; set -e
st='stages=["region","ca","smooth","density","shade","render_march"]'
"$0" run ci-small --backend cpu --quiet --out "$d/on" --set "$st" --set steps=12 --set warmup_steps=10 >/dev/null
"$0" run ci-small --backend cpu --quiet --out "$d/off" --set "$st" --set steps=12 --set warmup_steps=10 \
  --set march.skipping.enabled=false >/dev/null
test -s "$d/on/frame-march-above-cpu.png" && test -s "$d/on/frame-march-above-cpu.exr"
cmp "$d/on/frame-march-above-cpu.exr" "$d/off/frame-march-above-cpu.exr" && echo "same image"
/usr/bin/python3 - "$d" <<'PY'
import json, sys
def frames(name):
    r = json.load(open(sys.argv[1] + "/" + name + "/results.json"))
    return r["backends"]["cpu"]["march_frames"]["above"]
on, off = frames("on"), frames("off")
assert on["samples"][-1] < off["samples"][-1], (on["samples"], off["samples"])
assert on["light_samples"] == off["light_samples"], (on["light_samples"], off["light_samples"])
assert on["bricks_skipped"][-1] > 0 and off["bricks_skipped"][-1] == 0
print("fewer samples")
PY]=])
add_test(NAME Cli.MarchRunSkippingSameImage COMMAND /bin/sh -c "${cli_march_script}" ${cli} ${cli_out}/march)
set_tests_properties(Cli.MarchRunSkippingSameImage PROPERTIES TIMEOUT 120 PASS_REGULAR_EXPRESSION
                     "same image\nfewer samples")
