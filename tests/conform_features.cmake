# conform's deqp-runner features: the cover count, conform.csv,
# --baseline, --flake-reruns and --matrix, against the first non-CPU backend built, with a
# mismatch planted through the test-only CLOUDBENCH_TEST_CONFORM_MISMATCH switch.
# Included from tests/CMakeLists.txt, where `cli` and `cli_out` are defined.
if(CLOUDBENCH_HAVE_VK)
  set(conform_features_backend vk)
elseif(CLOUDBENCH_HAVE_GL)
  set(conform_features_backend gl)
endif()
if(DEFINED conform_features_backend)
  foreach(case IN ITEMS csv cover share baseline-expected baseline-new baseline-from-csv baseline-bad flaky flake-persistent
                        flaky-baseline usage matrix matrix-baseline)
    add_test(NAME Cli.ConformFeatures.${case}
             COMMAND /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/check_conform_features.py ${cli}
                     ${cli_out}/conform-features ${conform_features_backend} ${case})
    set_tests_properties(Cli.ConformFeatures.${case} PROPERTIES PASS_REGULAR_EXPRESSION
                         "conform features ${case}: ok" TIMEOUT 300)
  endforeach()
  # conform --junit, read back by Debian's python3-junitparser (skipped, 77, without it).
  add_test(NAME Cli.ConformJUnit
           COMMAND /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/check_junit.py ${cli} ${cli_out}/conform-junit
                   ${conform_features_backend})
  set_tests_properties(Cli.ConformJUnit PROPERTIES PASS_REGULAR_EXPRESSION "junit: ok" SKIP_RETURN_CODE 77 TIMEOUT 300)
endif()
# ci-small-wind (a 3x2 wind grid of distinct, asymmetric vectors) on every built
# backend, with the Khronos validation layer on; exit 4 (no backend besides the CPU could start) is a skip.
add_test(NAME Cli.ConformCiSmallWind COMMAND ${cli} conform ci-small-wind --steps 4 --out ${cli_out}/conform-wind)
set_tests_properties(Cli.ConformCiSmallWind PROPERTIES ENVIRONMENT CLOUDBENCH_VK_VALIDATION=1 SKIP_RETURN_CODE 4
                     FAIL_REGULAR_EXPRESSION "vk validation|fail ")
# placed-shapes (placed ellipsoids among random ones, SPEC 17) on every built backend, with the Khronos
# validation layer on (conform compares whole steps; TimeSliceLoop.PlacedEllipsoidsEqualTheUnslicedLoop the loop).
add_test(NAME Cli.ConformPlacedShapes COMMAND ${cli} conform placed-shapes --steps 30 --out ${cli_out}/conform-placed)
set_tests_properties(Cli.ConformPlacedShapes PROPERTIES ENVIRONMENT CLOUDBENCH_VK_VALIDATION=1 SKIP_RETURN_CODE 4
                     FAIL_REGULAR_EXPRESSION "vk validation|fail " TIMEOUT 600)
# render_splat at 2176 x 1440 (every built backend) and 3840 x 2160 (vk: gl's images hold at most 2048
# rows here, and says so): above 48 000 screen tiles vk's binning used to run an invocation's loops past
# lavapipe's budget of 65535 iterations in all, which ends them silently, and above 65535 tiles its serial
# scan of the tiles likewise; the images then differed from the CPU's in every tile from the cut on
# (docs/performance.md, "vk render_splat at large images"). ci-small, 6 steps: a few seconds each.
add_test(NAME Cli.ConformLargeImage.2176x1440
         COMMAND ${cli} conform ci-small --steps 6 --set render.width=2176 --set render.height=1440
                 --out ${cli_out}/conform-large-2176x1440)
set_tests_properties(Cli.ConformLargeImage.2176x1440 PROPERTIES SKIP_RETURN_CODE 4 FAIL_REGULAR_EXPRESSION "fail"
                     TIMEOUT 300)
if(CLOUDBENCH_HAVE_VK)
  add_test(NAME Cli.ConformLargeImage.3840x2160
           COMMAND ${cli} conform ci-small --backend vk --steps 6 --set render.width=3840 --set render.height=2160
                   --out ${cli_out}/conform-large-3840x2160)
  set_tests_properties(Cli.ConformLargeImage.3840x2160 PROPERTIES SKIP_RETURN_CODE 4 FAIL_REGULAR_EXPRESSION "fail"
                       TIMEOUT 300)
endif()
# 255-pixel splats (the size limit) over a 2176 x 1440 image, every built backend: with 673 splats, each up to
# 33 x 33 screen tiles, vk's old binning looped per chunk of 256 splats over their tiles past lavapipe's budget
# and 580 610 pixels differed from the CPU's; its (screen tile, splat) pairs sorted by tile bound every loop
# (docs/performance.md, "vk render_splat: pairs sorted by tile").
add_test(NAME Cli.ConformLargeSplats
         COMMAND ${cli} conform ci-small --steps 6 --set render.width=2176 --set render.height=1440
                 --set render.splat_scale=4 --set "render.cameras=[{\"name\":\"close\",\"eye\":[1600,1600,3000],\"target\":[1600,1620,0],\"up\":[0,0,1],\"fov_deg\":20,\"near\":1,\"far\":20000}]"
                 --out ${cli_out}/conform-large-splats)
set_tests_properties(Cli.ConformLargeSplats PROPERTIES SKIP_RETURN_CODE 4 FAIL_REGULAR_EXPRESSION "fail"
                     TIMEOUT 300)
# NaN, +Inf and -Inf planted through the test-only CLOUDBENCH_TEST_CONFORM_MISMATCH_VALUE switch in the first
# element of a row, in the first non-CPU backend's output (Cli.ConformNonFinite.<rule>.<value>) or in the CPU
# reference's (Cli.ConformNonFinite.<rule>.cpu<value>), under each kind of comparison rule: bit-exact (smooth's q),
# absolute (shade's T on fp32), stored codes (T on unorm8, where a clamp would turn an Inf into a code), the image
# rule with a limit (render_splat) and without one (render_march: |d| <= 1e-4 on 99.9 % of the pixels, where one Inf
# pixel is within the share). conform exits 5 and its table names the step, the element and both values.
if(DEFINED conform_features_backend)
  foreach(rule IN ITEMS bit-exact absolute codes image image-unlimited)
    set(nonfinite_scene ci-small)
    set(nonfinite_sets "")
    set(nonfinite_where "step 0 at (0, 0, 0)")
    if(rule STREQUAL "bit-exact")
      set(nonfinite_stage smooth)
    elseif(rule STREQUAL "absolute")
      set(nonfinite_stage shade)
    elseif(rule STREQUAL "codes")
      set(nonfinite_stage shade)
      set(nonfinite_sets "--set shade.storage=unorm8")
    elseif(rule STREQUAL "image")
      set(nonfinite_stage render_splat)
      set(nonfinite_where "step 0 camera above pixel (0, 0) channel 0")
    else()
      set(nonfinite_stage render_march)
      set(nonfinite_scene noise-layer)
      set(nonfinite_sets "--set grid.size=[32,32,16] --set render.width=32 --set render.height=24")
      set(nonfinite_where "step 0 camera above pixel (0, 0) channel 0")
    endif()
    foreach(side IN ITEMS "" cpu)
      set(nonfinite_target ${conform_features_backend})
      if(side STREQUAL "cpu")
        set(nonfinite_target cpu)
      endif()
      foreach(value IN ITEMS nan inf -inf)
        add_test(NAME Cli.ConformNonFinite.${rule}.${side}${value} COMMAND /bin/sh -c [=[
          mkdir -p "$(dirname "$2")"
          "$0" conform "$4" --steps 1 --backend "$1" --out "$2" $6 > "$2.log" 2>&1; rc=$?
          cat "$2.log"
          want="cpu [0-9.e+-]*, $1 $3"
          [ "$7" = cpu ] && want="cpu $3, $1 [0-9.e+-]*"
          [ "$rc" = 5 ] && grep -q "$5: not finite: $want" "$2.log" && echo "conform non-finite: ok"
        ]=] ${cli} ${conform_features_backend} ${cli_out}/conform-nonfinite-${rule}-${side}${value} ${value}
            ${nonfinite_scene} "${nonfinite_where}" "${nonfinite_sets}" "${nonfinite_target}")
        set_tests_properties(Cli.ConformNonFinite.${rule}.${side}${value} PROPERTIES PASS_REGULAR_EXPRESSION
                             "conform non-finite: ok" TIMEOUT 300 ENVIRONMENT
                             "CLOUDBENCH_TEST_CONFORM_MISMATCH=${nonfinite_target}:${nonfinite_stage};CLOUDBENCH_TEST_CONFORM_MISMATCH_VALUE=${value}")
      endforeach()
    endforeach()
  endforeach()
endif()
# Wang, Ji and Zhang's light terms, city glow (one blob off the diagonal x = y, so that a swapped x and y shows) and
# eye scattering (a 90-degree cone), on every built backend for each renderer: a splat (ci-small), a march
# (noise-layer) and a layers (layers-small) scene; exit 4 (no backend besides the CPU could start) is a skip.
foreach(scene IN ITEMS ci-small noise-layer layers-small)
  add_test(NAME Cli.ConformWangLight.${scene}
           COMMAND ${cli} conform ${scene} --steps 2 --set warmup_steps=0
                   --set "lighting.city_glow={\"color\":[1,0.5,0.2],\"blobs\":[{\"center\":[1600,900],\"radius\":1000,\"strength\":2}]}"
                   --set "lighting.eye_scattering={\"intensity\":2,\"cone_deg\":90,\"height_gain\":1}"
                   --out ${cli_out}/conform-wang-light-${scene})
  set_tests_properties(Cli.ConformWangLight.${scene} PROPERTIES SKIP_RETURN_CODE 4 FAIL_REGULAR_EXPRESSION "fail"
                       TIMEOUT 300)
endforeach()
# Multiple-scattering octaves (4, with a 0.5, b 0.7, c 0.5) on every built backend for each renderer: splats
# (ci-small), the march (imgacc-small, beside splats) and the layers (layers-small); exit 4 (no backend besides the CPU
# could start) is a skip.
foreach(scene IN ITEMS ci-small imgacc-small layers-small)
  set(scene_path ${scene})
  if(scene STREQUAL "imgacc-small")
    set(scene_path ${CMAKE_CURRENT_SOURCE_DIR}/scenes/imgacc-small.json)
  endif()
  add_test(NAME Cli.ConformOctaves.${scene}
           COMMAND ${cli} conform ${scene_path} --steps 2 --set warmup_steps=0
                   --set "lighting.octaves={\"count\":4,\"attenuation\":0.5,\"contribution\":0.7,\"eccentricity\":0.5}"
                   --out ${cli_out}/conform-octaves-${scene})
  set_tests_properties(Cli.ConformOctaves.${scene} PROPERTIES SKIP_RETURN_CODE 4 FAIL_REGULAR_EXPRESSION "fail"
                       TIMEOUT 300)
endforeach()
# Octaves that keep the extinction and the phase (a = b = c = 1, 3 of them) triple every renderer's image on every
# backend (no ambient light, a black background): conform cannot see a renderer that ignores the octaves on every
# backend alike, this can (tests/check_octaves_scale.py).
add_test(NAME Cli.OctavesScaleEveryRenderer
         COMMAND /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/check_octaves_scale.py ${cli} ${cli_out}/octaves-scale)
set_tests_properties(Cli.OctavesScaleEveryRenderer PROPERTIES PASS_REGULAR_EXPRESSION "octaves scale: ok" TIMEOUT 300)
# Tiling in the march: layers-small's tiled clouds out to its 20 km far plane, drawn by render_march beside
# render_layers (shade's T, then the light march, whose light crosses the neighbouring tiles), on every built
# backend; exit 4 (no backend besides the CPU could start) is a skip.
foreach(light IN ITEMS shade march)
  add_test(NAME Cli.ConformTiledMarch.${light}
           COMMAND ${cli} conform layers-small --set "stages=[\"noise\",\"shade\",\"render_march\",\"render_layers\"]"
                   --set "march.light=\"${light}\"" --out ${cli_out}/conform-tiled-march-${light})
  set_tests_properties(Cli.ConformTiledMarch.${light} PROPERTIES SKIP_RETURN_CODE 4 FAIL_REGULAR_EXPRESSION "fail"
                       PASS_REGULAR_EXPRESSION "render_march +(gl|vk) +pass" TIMEOUT 300)
endforeach()
# The sky light, low and off the diagonal (so that a swapped x and y shows), with its own T_sky, on every built
# backend for each renderer: the splats (ci-small, whose automaton runs two steps), the march (tiled layers-small,
# shade's T and then the light march, which still reads T_sky) and the layers, at shade resolution 1 and 2 (the sky's
# coarse sweep beside the sun's); exit 4 (no backend besides the CPU could start) is a skip.
set(sky_light "lighting.sky={\"elevation_deg\":12,\"azimuth_deg\":200,\"color\":[1,0.5,0.3],\"intensity\":1.5}")
foreach(resolution IN ITEMS 1 2)
  add_test(NAME Cli.ConformSkyLight.splat-${resolution}
           COMMAND ${cli} conform ci-small --steps 2 --set warmup_steps=0 --set "${sky_light}"
                   --set "stages=[\"region\",\"ca\",\"smooth\",\"density\",\"shade\",\"shade_sky\",\"render_splat\"]"
                   --set shade.resolution=${resolution} --out ${cli_out}/conform-sky-splat-${resolution})
  set_tests_properties(Cli.ConformSkyLight.splat-${resolution} PROPERTIES SKIP_RETURN_CODE 4
                       FAIL_REGULAR_EXPRESSION "fail" PASS_REGULAR_EXPRESSION "shade_sky +(gl|vk) +pass" TIMEOUT 300)
  foreach(light IN ITEMS shade march)
    add_test(NAME Cli.ConformSkyLight.${light}-${resolution}
             COMMAND ${cli} conform layers-small --set "${sky_light}"
                     --set "stages=[\"noise\",\"shade\",\"shade_sky\",\"render_march\",\"render_layers\"]"
                     --set "march.light=\"${light}\"" --set shade.resolution=${resolution}
                     --out ${cli_out}/conform-sky-${light}-${resolution})
    set_tests_properties(Cli.ConformSkyLight.${light}-${resolution} PROPERTIES SKIP_RETURN_CODE 4
                         FAIL_REGULAR_EXPRESSION "fail" PASS_REGULAR_EXPRESSION "render_layers +(gl|vk) +pass"
                         TIMEOUT 300)
  endforeach()
endforeach()
# Shafts of light (SPEC 18) on every built backend: in splat and march frames over automaton clouds (crepuscular)
# and in layer frames over a tiled noise layer (layers-small with the density stage); exit 4 (no backend besides the
# CPU could start) is a skip.
add_test(NAME Cli.ConformShafts.crepuscular
         COMMAND ${cli} conform crepuscular --steps 6 --set warmup_steps=0 --out ${cli_out}/conform-shafts-crepuscular)
add_test(NAME Cli.ConformShafts.layers-small
         COMMAND ${cli} conform layers-small --steps 2 --set warmup_steps=0
                 --set "stages=[\"noise\",\"density\",\"shade\",\"render_layers\"]"
                 --set "lighting.shafts={\"shells\":24,\"extinction\":0.0002,\"falloff_deg\":60}"
                 --out ${cli_out}/conform-shafts-layers)
set_tests_properties(Cli.ConformShafts.crepuscular Cli.ConformShafts.layers-small PROPERTIES
                     ENVIRONMENT CLOUDBENCH_VK_VALIDATION=1 SKIP_RETURN_CODE 4
                     FAIL_REGULAR_EXPRESSION "vk validation|fail " TIMEOUT 300)
# The shafts are added to every renderer's frame on every backend, the same light whatever the renderer
# (tests/check_shafts_added.py): conform cannot see a renderer that misses them on every backend alike, this can.
add_test(NAME Cli.ShaftsAddedToEveryRenderer
         COMMAND /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/check_shafts_added.py ${cli} ${cli_out}/shafts-added)
set_tests_properties(Cli.ShaftsAddedToEveryRenderer PROPERTIES PASS_REGULAR_EXPRESSION "shafts added: ok" TIMEOUT 300)
