// GLSL twin of core/math/Ground.h: the ground plane z = origin_z lit through G,
// the background of a pixel for both renderers (docs/pipeline.md, "The ground
// in the frame"). The same operations in the same order as the C++, `precise`
// where the CPU (built with -ffp-contract=off) rounds each product.
//
// Include after shading.glsl. The including shader DEFINES
//   float GroundFetchG(uint i, uint j);  // G of ground cell (i, j), 0 <= i < nx, 0 <= j < ny
#ifndef CLOUDBENCH_GROUND_GLSL
#define CLOUDBENCH_GROUND_GLSL

// core/math/Ground.h GroundGpu, row for row.
struct GroundGpu {
    vec4 eye;          // xyz voxel units; w focalPx
    vec4 forward;      // w near (metres)
    vec4 right;        // w far (metres)
    vec4 up;           // w voxel size h (metres)
    vec4 albedo;       // rgb; w s_z
    vec4 sunRadiance;  // rgb
    vec4 ambient;      // rgb
    vec4 background;   // rgb: the flat background
    uvec4 grid;        // nx, ny of G; width, height
};

float GroundFetchG(uint i, uint j);

// core/math/Ground.h GroundHit: where o + t d meets z = 0 with t in [tNear, tFar].
bool GroundHit(vec3 o, vec3 d, float tNear, float tFar, out vec2 p) {
    p = vec2(0.0);
    if (!(d.z < 0.0)) return false;
    precise float t = (0.0 - o.z) / d.z;
    if (!(t >= tNear && t <= tFar)) return false;
    precise float x = o.x + d.x * t;
    precise float y = o.y + d.y * t;
    p = vec2(x, y);
    return true;
}

// core/math/Ground.h GroundShadowAt with the fetch GroundFetchG.
float GroundShadowAt(float x, float y, uint nx, uint ny) {
    if (!(x >= 0.0 && x <= float(nx) && y >= 0.0 && y <= float(ny))) return 1.0;
    precise float cx = clamp(x - 0.5, 0.0, float(nx - 1u));
    precise float cy = clamp(y - 0.5, 0.0, float(ny - 1u));
    const uint i0 = uint(cx), j0 = uint(cy);
    const uint i1 = min(i0 + 1u, nx - 1u), j1 = min(j0 + 1u, ny - 1u);
    precise float fu = cx - float(i0);
    precise float fv = cy - float(j0);
    return Bilinear(GroundFetchG(i0, j0), GroundFetchG(i1, j0), GroundFetchG(i0, j1), GroundFetchG(i1, j1), fu, fv);
}

// core/math/Ground.h GroundChannel: albedo (sunRadiance max(s_z, 0) G + ambient).
float GroundChannel(float albedo, float sunRadiance, float sunZ, float ambient, float g) {
    precise float r = albedo * (sunRadiance * max(sunZ, 0.0) * g + ambient);
    return r;
}

// core/math/Ground.h GroundBackground of pixel (x, y); the ray as march.glsl's MakePixelRay builds it.
vec3 GroundBackground(GroundGpu g, uint x, uint y) {
    const float focal = g.eye.w;
    precise float u = (float(x) + 0.5 - 0.5 * float(g.grid.z)) / focal;
    precise float v = (0.5 * float(g.grid.w) - (float(y) + 0.5)) / focal;
    precise vec3 d;
    for (int i = 0; i < 3; ++i) d[i] = g.forward[i] + u * g.right[i] + v * g.up[i];
    precise float dd = d.x * d.x + d.y * d.y + d.z * d.z;
    precise float inv = 1.0 / sqrt(dd);
    precise vec3 dir = vec3(d.x * inv, d.y * inv, d.z * inv);
    precise float perDepth = 1.0 / (g.up.w * inv);
    precise float tNear = g.forward.w * perDepth;
    precise float tFar = g.right.w * perDepth;
    vec2 p;
    if (!GroundHit(g.eye.xyz, dir, tNear, tFar, p)) return g.background.rgb;
    const float s = GroundShadowAt(p.x, p.y, g.grid.x, g.grid.y);
    return vec3(GroundChannel(g.albedo.x, g.sunRadiance.x, g.albedo.w, g.ambient.x, s),
                GroundChannel(g.albedo.y, g.sunRadiance.y, g.albedo.w, g.ambient.y, s),
                GroundChannel(g.albedo.z, g.sunRadiance.z, g.albedo.w, g.ambient.z, s));
}

#endif
