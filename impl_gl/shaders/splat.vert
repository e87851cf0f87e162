#include "random.glsl"
#include "rules.glsl"
#include "shading.glsl"
#include "automaton.glsl"
#include "phase_table.glsl"
#include "light.glsl"
#include "splat.glsl"
// Stage `render_splat` (SPEC 8), the thesis's way (its chapter 6): one
// GL_POINTS vertex per voxel, drawn in the shared back-to-front order (the
// vertex id is the voxel's rank), so blending composites in that order. The
// vertex shader reads the volumes and throws away voxels that make no splat
// (section 6.2) by placing them outside the clip volume. With deviceSkip (in
// a batch) it also throws away the voxels of tile x band boxes empty
// in both steps' bands, which the host's runs skip otherwise, and counts the rest.
layout(std430, binding = 0) readonly buffer Order { uint orderIndex[]; };  // outer, middle, inner axis orders
layout(std430, binding = 1) buffer Counters { uint splatCount; uint visitedCount; };
layout(binding = 4) uniform usampler2DArray bandsPrevMap;
layout(binding = 5) uniform usampler2DArray bandsCurMap;
uniform int deviceSkip;
uniform ivec2 tileBand;
layout(std430, binding = 2) readonly buffer Frame { SplatFrame F; };  // maxPointSize: the largest point size
layout(std430, binding = 3) readonly buffer PhaseTable { float phaseTable[]; };  // read with phase Mie only
float PhaseTableValue(uint i) { return phaseTable[i]; }
layout(binding = 0) uniform sampler2DArray qPrev;
layout(binding = 1) uniform sampler2DArray qCur;
layout(binding = 2) uniform sampler2DArray transmittance;
layout(binding = 6) uniform sampler2DArray skyTransmittance;  // the sky light's T_sky, read with it on only
uniform float guard;       // pixels of viewport beyond each image edge
flat out vec4 colour;      // rgb, q_alpha * opacity
flat out vec3 splat;       // px, py, size (pixels; row 0 at the top)

void Reject() {
    gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
    gl_PointSize = 1.0;
}

void main() {
    const int rank = gl_VertexID;
    const int nMid = int(F.grid[F.axes.y]), nIn = int(F.grid[F.axes.z]);
    ivec3 idx;
    idx[F.axes.x] = int(orderIndex[F.orderBase.x + uint(rank / (nMid * nIn))]);
    idx[F.axes.y] = int(orderIndex[F.orderBase.y + uint((rank % (nMid * nIn)) / nIn)]);
    idx[F.axes.z] = int(orderIndex[F.orderBase.z + uint(rank % nIn)]);
    if (deviceSkip != 0) {
        const ivec3 box = ivec3(idx.x / tileBand.x, idx.y / tileBand.x, idx.z / tileBand.y);
        if (texelFetch(bandsPrevMap, box, 0).r == 0u && texelFetch(bandsCurMap, box, 0).r == 0u) {
            Reject();
            return;
        }
        atomicAdd(visitedCount, 1u);
    }
    const float qa = SplatQ(texelFetch(qPrev, idx, 0).r, texelFetch(qCur, idx, 0).r, F.alpha);
    Splat s;
    const float tSky = F.light.skyOn != 0u ? texelFetch(skyTransmittance, idx, 0).r : 1.0;
    if (!MakeSplat(F, uvec3(idx), qa, texelFetch(transmittance, idx, 0).r, tSky, s)) {
        Reject();
        return;
    }
    colour = vec4(s.r, s.g, s.b, s.alphaScale);
    splat = vec3(s.px, s.py, s.size);
    atomicAdd(splatCount, 1u);
    // Window y = py, so framebuffer row 0 is the image's top row. The point is
    // drawn two pixels wider than the splat and the fragment shader keeps
    // exactly SPEC 8's coverage; the viewport's guard band keeps points whose
    // centre is just off the image from being clipped whole.
    const vec2 viewport = vec2(F.width, F.height) + 2.0 * guard;
    gl_Position = vec4((vec2(s.px, s.py) + guard) / viewport * 2.0 - 1.0, 0.0, 1.0);
    gl_PointSize = min(s.size + 2.0, F.maxPointSize);
}
