# The shipped ray-march scenes through the CLI. Included from tests/CMakeLists.txt where `cli`
# and `cli_out` are set.
# lightning.json flashes at step 2 of 4 and its clouds are static: the last frame of a 2-step run (before the
# flash) and of a 4-step run (after it) must be the same pixels, and the 3-step run's last frame (the flash) must
# be brighter, most of all near the light. Small images keep it fast; the clouds are the scene's own 128^3.
set(cli_scenes_lightning_script [=[d="$1"; rm -rf "$d"; set -e
for n in 2 3 4; do
  "$0" run lightning --backend cpu --quiet --out "$d/s$n" --steps $n --set render.width=96 --set render.height=54 >/dev/null
done
/usr/bin/python3 - "$d" "$2" <<'PY'
import pathlib, sys
sys.path.insert(0, sys.argv[2])
from check_bad_inputs import exr_floats
before, flash, after = (exr_floats(pathlib.Path(sys.argv[1]) / f"s{n}" / "frame-march-storm-cpu.exr") for n in (2, 3, 4))
assert before.size == 96 * 54 * 3, before.size
assert (before == after).all(), "the frames before and after the flash differ"
print("same before and after")
assert (flash >= before).all(), "the flash darkened a pixel"
assert flash.mean() > 1.05 * before.mean() and flash.max() > 2 * before.max(), (before.mean(), flash.mean(), before.max(), flash.max())
print("brighter during the flash")
PY]=])
add_test(NAME Cli.ScenesLightningFlash COMMAND /bin/sh -c "${cli_scenes_lightning_script}" ${cli} ${cli_out}/scenes-lightning
         ${CMAKE_CURRENT_SOURCE_DIR})
set_tests_properties(Cli.ScenesLightningFlash PROPERTIES TIMEOUT 120 PASS_REGULAR_EXPRESSION
                     "same before and after\nbrighter during the flash")

# tools/olajos_tables.py keeps working: one quick round (320x180), every row printed. Not a measurement.
add_test(NAME Cli.OlajosTablesQuick COMMAND /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/../tools/olajos_tables.py
         --quick --cli ${cli} --out ${cli_out}/olajos-quick)
set_tests_properties(Cli.OlajosTablesQuick PROPERTIES TIMEOUT 120 PASS_REGULAR_EXPRESSION
                     "3\\.1 skip structure off / on[^\n]*\n[^\n]*3\\.2 adaptive[^\n]*\n[^\n]*3\\.2 adaptive[^\n]*\n[^\n]*3\\.3 light[^\n]*\n[^\n]*3\\.4 phase")
