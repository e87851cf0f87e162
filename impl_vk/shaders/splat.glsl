// Shared by the splat passes (SPEC 8): the frame parameters and MakeSplat,
// which turns the voxel of a given rank in the shared back-to-front order
// into a splat, with the same arithmetic as impl_cpu/RenderSplatCpu.cpp.
#ifndef CLOUDBENCH_SPLAT_GLSL
#define CLOUDBENCH_SPLAT_GLSL
#extension GL_EXT_shader_8bit_storage : require
#include "shading.glsl"

struct Splat {
    float px, py, size, alphaScale;
    float r, g, b, pad;
    int x0, x1, y0, y1;
};

layout(std430, binding = 0) readonly buffer QPrev { float qPrev[]; };
layout(std430, binding = 1) readonly buffer QCur { float qCur[]; };
layout(std430, binding = 2) readonly buffer Transmittance { float transmittance[]; };
layout(std430, binding = 3) readonly buffer Order { uint orderIndex[]; };  // outer, middle, inner axis orders
layout(std430, binding = 4) readonly buffer Boxes { uint8_t boxVisible[]; };
layout(std430, binding = 5) readonly buffer Frame {
    uvec4 grid;        // nx, ny, nz, voxels per chunk
    uvec4 axes;        // outer, middle, inner axis, voxel count
    uvec4 orderBase;   // where each axis's order starts in orderIndex (outer, middle, inner)
    uvec4 boxes;       // tile, band, tilesX, tilesY
    uvec4 image;       // width, height, screen tiles across, screen tiles down
    vec4 eye;          // xyz, near
    vec4 forward;      // xyz, focal length in pixels
    vec4 right;
    vec4 up;
    vec4 sun;          // xyz toward the sun, phase g
    vec4 sunRadiance;  // rgb, phase kind
    vec4 ambient;      // rgb, q_min
    vec4 background;   // rgb, opacity
    vec4 origin;       // xyz, voxel size
    vec4 misc;         // splat diameter, alpha
} F;

uint AxisSize(uint axis) { return axis == 0u ? F.grid.x : (axis == 1u ? F.grid.y : F.grid.z); }

bool MakeSplat(uint rank, out Splat s) {
    s = Splat(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0, -1, 0, -1);
    const uint nMid = AxisSize(F.axes.y), nIn = AxisSize(F.axes.z);
    const uint o = rank / (nMid * nIn), rest = rank % (nMid * nIn);
    uint idx[3];
    idx[F.axes.x] = orderIndex[F.orderBase.x + o];
    idx[F.axes.y] = orderIndex[F.orderBase.y + rest / nIn];
    idx[F.axes.z] = orderIndex[F.orderBase.z + rest % nIn];
    const uint i = idx[0], j = idx[1], k = idx[2];
    const uint box = i / F.boxes.x + F.boxes.z * (j / F.boxes.x + F.boxes.w * (k / F.boxes.y));
    if (uint(boxVisible[box]) == 0u) return false;
    const uint v = i + F.grid.x * (j + F.grid.y * k);
    precise float qa = qPrev[v] + F.misc.y * (qCur[v] - qPrev[v]);
    if (!(qa > F.ambient.w)) return false;
    const float h = F.origin.w;
    precise vec3 centre = vec3(F.origin.x + (float(i) + 0.5) * h, F.origin.y + (float(j) + 0.5) * h,
                               F.origin.z + (float(k) + 0.5) * h);
    precise float dx = centre.x - F.eye.x, dy = centre.y - F.eye.y, dz = centre.z - F.eye.z;
    precise float x = dx * F.right.x + dy * F.right.y + dz * F.right.z;
    precise float y = dx * F.up.x + dy * F.up.y + dz * F.up.z;
    precise float depth = dx * F.forward.x + dy * F.forward.y + dz * F.forward.z;
    if (!(depth > F.eye.w)) return false;
    const float focal = F.forward.w;
    precise float px = 0.5 * float(F.image.x) + x * focal / depth;
    precise float py = 0.5 * float(F.image.y) - y * focal / depth;
    precise float size = clamp(F.misc.x * focal / depth, 1.0, 255.0);
    precise float len = sqrt(dx * dx + dy * dy + dz * dz);
    precise float cosTheta = (F.sun.x * dx + F.sun.y * dy + F.sun.z * dz) / len;
    precise float light = transmittance[v] * PhaseValue(uint(F.sunRadiance.w), F.sun.w, cosTheta);
    s.px = px;
    s.py = py;
    s.size = size;
    s.alphaScale = qa * F.background.w;
    s.r = F.sunRadiance.x * light + F.ambient.x;
    s.g = F.sunRadiance.y * light + F.ambient.y;
    s.b = F.sunRadiance.z * light + F.ambient.z;
    precise float halfSize = 0.5 * size;
    s.x0 = int(max(0.0, ceil(px - halfSize - 0.5)));
    s.x1 = int(min(float(F.image.x) - 1.0, ceil(px + halfSize - 0.5) - 1.0));
    s.y0 = int(max(0.0, ceil(py - halfSize - 0.5)));
    s.y1 = int(min(float(F.image.y) - 1.0, ceil(py + halfSize - 0.5) - 1.0));
    return true;
}

#endif
