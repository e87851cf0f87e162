#version 450
// Stage `render_march` (SPEC 10), pass 3: one invocation per pixel in 8 x 8
// workgroups, MarchPixel of core/math/march.glsl, which twins core/math/March.h
// MarchRay line by line. Reads the padded volume of pass 1 (march_volume.comp),
// the bricks of pass 2 (march_bricks.comp) when skipping, the Mie table when
// the phase is Mie, T_sky's padded volume (sky_volume.comp) with the sky light; writes linear HDR RGB and adds the MarchStats counters
// (a reduction in shared memory, then one atomic per workgroup and counter).
#extension GL_GOOGLE_include_directive : require
#define MARCH_WITH_T 1
#include "render_march.glsl"
