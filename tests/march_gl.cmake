# Stage render_march on OpenGL from the command line (issue 14 item 2): conform runs the GL backend on the
# CPU's inputs and compares by SPEC 10's rule (1e-4 per linear channel on 99.9 % of pixels). Included from
# tests/CMakeLists.txt.
if(CLOUDBENCH_HAVE_GL)
  set(march_gl_stages "stages=[\"noise\",\"density\",\"shade\",\"render_march\"]")
  add_test(NAME Cli.ConformMarchGl
           COMMAND ${cli} conform ${CMAKE_CURRENT_SOURCE_DIR}/scenes/imgacc-small.json --backend cpu,gl
                   --set ${march_gl_stages} --out ${cli_out}/conform-march-gl)
  set_tests_properties(Cli.ConformMarchGl PROPERTIES PASS_REGULAR_EXPRESSION "render_march +gl +pass")
  # Odd grid and image, jitter, adaptive steps, brick 5, the light march, Mie, powder and the point light at once.
  add_test(NAME Cli.ConformMarchGlEveryOption
           COMMAND ${cli} conform ${CMAKE_CURRENT_SOURCE_DIR}/scenes/imgacc-small.json --backend cpu,gl
                   --set ${march_gl_stages} --set grid.size=[31,29,13] --set render.width=37
                   --set render.height=23 --set march.jitter=true --set march.adaptive.enabled=true
                   --set march.adaptive.start=4 --set march.skipping.brick=5 --set march.light=march
                   --set phase.function=mie --set march.powder.enabled=true
                   --set lightning.position=[800,800,300] --out ${cli_out}/conform-march-gl-options)
  set_tests_properties(Cli.ConformMarchGlEveryOption PROPERTIES PASS_REGULAR_EXPRESSION "render_march +gl +pass")
endif()
