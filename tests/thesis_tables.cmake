# Tables 8.2-8.4's image rule (SPEC 8): culling and empty-space skipping never change the image.
# Included from tests/CMakeLists.txt where `cli` and `cli_out` are set.
#
# ci-small on every built backend (exit 4, a backend missing: the others still checked) under the three settings of
# the thesis's tables -- none, view-frustum culling (VFD), VFD + empty-space skipping (ESS) -- at alpha 0.5 (q and
# the occupancy interpolated between two steps), with cameras whose frustum edges cut the clouds: "inside" stands in
# the grid at cloud height and looks along +y with a 40 degree view (tiles beside and behind it are outside),
# "corner" looks down onto one corner (most of the grid is outside), and "edge" stands at cloud height at x = 790 m
# and turns by the horizontal half field of view (atan(4/3 tan 20 deg) = 25.885 deg), so its left side plane is the
# plane x = 790 m: the voxel centres of the first tile column (x <= 775 m) lie 15 m outside it, but their splats (75 m
# wide) reach into the view -- a cull without the half-splat margin changes this image (checked: 6906 values of
# the cpu image change). Every camera's EXR must be bit for bit the same under the three settings per backend.
# Where the backend counts the voxels it read (cpu, gl), culling must read fewer for the cutting cameras, and
# skipping fewer still -- otherwise the test would not test culling.
set(cli_thesis_tables_script [=[cli="$0"; d="$1"; src="$2"; rm -rf "$d"; set -e
cams='[{"name":"above","eye":[-400,-400,1800],"target":[1600,1600,300]},
{"name":"inside","eye":[1600,200,320],"target":[1600,3000,380],"fov_deg":40},
{"name":"corner","eye":[-300,-300,1500],"target":[500,500,300],"fov_deg":30},
{"name":"edge","eye":[790,100,320],"target":[2099.7,2799.0,320],"fov_deg":40}]'
for s in "none false false" "vfd true false" "vfd_ess true true"; do
  set -- $s
  "$cli" run ci-small --quiet --out "$d/$1" --set steps=12 --set warmup_steps=10 --set render.every_steps=1 \
    --set render.alpha=0.5 --set "render.cameras=$cams" --set render.culling=$2 --set render.skipping=$3 \
    >/dev/null || test $? -eq 4
done
/usr/bin/python3 - "$d" "$src" <<'PY'
import json, pathlib, sys
sys.path.insert(0, sys.argv[2])
from check_bad_inputs import exr_floats  # the pixels, not the header (which holds a time stamp)
d = pathlib.Path(sys.argv[1])
res = {k: json.load(open(d / k / "results.json"))["backends"] for k in ("none", "vfd", "vfd_ess")}
ok = [b for b, r in res["none"].items() if r["status"] == "ok"]
assert "cpu" in ok, res["none"].keys()
for b in ok:
    assert all(res[k][b]["status"] == "ok" for k in res), b
    for cam in ("above", "inside", "corner", "edge"):
        imgs = {k: exr_floats(next((d / k).glob(f"frame*-{cam}-{b}.exr"))) for k in res}
        assert imgs["none"].size == 160 * 120 * 3, (b, cam, imgs["none"].size)
        assert imgs["none"].max() > imgs["none"].min(), (b, cam, "a flat image tests nothing")
        for k in ("vfd", "vfd_ess"):
            diff = int((imgs[k] != imgs["none"]).sum())
            assert diff == 0, f"{b} {cam}: {k} changes {diff} of {imgs[k].size} values"
        visited = {k: res[k][b]["frames"][cam]["voxels_visited"][-1] for k in res}
        if visited["none"] > 0:  # this backend counts them
            assert visited["none"] == 64 * 64 * 16, (b, cam, visited)
            if cam != "above":
                assert visited["vfd"] < visited["none"], (b, cam, visited)
            assert visited["vfd_ess"] < visited["vfd"], (b, cam, visited)
        print(b, cam, "identical", visited)
print("images identical across culling settings")
PY]=])
add_test(NAME Cli.ThesisTablesSameImage COMMAND /bin/sh -c "${cli_thesis_tables_script}" ${cli}
         ${cli_out}/thesis-tables ${CMAKE_CURRENT_SOURCE_DIR})
set_tests_properties(Cli.ThesisTablesSameImage PROPERTIES TIMEOUT 120 PASS_REGULAR_EXPRESSION
                     "images identical across culling settings")
