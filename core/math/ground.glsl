// GLSL twin of core/math/Ground.h: the ground plane z = origin_z lit through G,
// the background of a pixel for both renderers (docs/pipeline.md, "The ground
// in the frame"). The same operations in the same order as the C++, `precise`
// where the CPU (built with -ffp-contract=off) rounds each product.
//
// Include after shading.glsl. The including shader DEFINES
//   float GroundFetchG(uint i, uint j);  // G of ground cell (i, j), 0 <= i < nx, 0 <= j < ny
#ifndef CLOUDBENCH_GROUND_GLSL
#define CLOUDBENCH_GROUND_GLSL

// core/math/Ground.h GroundGpu, member for member.
struct GroundGpu {
    vec3 eye;  // voxel units
    float focalPx;
    vec3 forward;
    float nearPlane;  // metres
    vec3 right;
    float farPlane;  // metres
    vec3 up;
    float voxelSize;  // h, metres
    vec3 albedo;
    float sunZ;
    vec3 sunRadiance;
    float unused0;
    vec3 ambient;
    float unused1;
    vec3 background;  // the flat background
    float unused2;
    uint gridX;  // nx of G
    uint gridY;  // ny of G
    uint width;
    uint height;
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
    const float focal = g.focalPx;
    precise float u = (float(x) + 0.5 - 0.5 * float(g.width)) / focal;
    precise float v = (0.5 * float(g.height) - (float(y) + 0.5)) / focal;
    precise vec3 d;
    for (int i = 0; i < 3; ++i) d[i] = g.forward[i] + u * g.right[i] + v * g.up[i];
    precise float dd = d.x * d.x + d.y * d.y + d.z * d.z;
    precise float inv = 1.0 / sqrt(dd);
    precise vec3 dir = vec3(d.x * inv, d.y * inv, d.z * inv);
    precise float perDepth = 1.0 / (g.voxelSize * inv);
    precise float tNear = g.nearPlane * perDepth;
    precise float tFar = g.farPlane * perDepth;
    vec2 p;
    if (!GroundHit(g.eye, dir, tNear, tFar, p)) return g.background;
    const float s = GroundShadowAt(p.x, p.y, g.gridX, g.gridY);
    return vec3(GroundChannel(g.albedo.x, g.sunRadiance.x, g.sunZ, g.ambient.x, s),
                GroundChannel(g.albedo.y, g.sunRadiance.y, g.sunZ, g.ambient.y, s),
                GroundChannel(g.albedo.z, g.sunRadiance.z, g.sunZ, g.ambient.z, s));
}

#endif
