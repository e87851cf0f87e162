#version 450
// Stage `render_march`, pass 3 with the light source "march": render_march.glsl over a volume of q_alpha alone.
#extension GL_GOOGLE_include_directive : require
#define MARCH_WITH_T 0
#include "render_march.glsl"
