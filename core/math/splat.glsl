// GLSL twin of core/math/Splat.h (SPEC 8): the frame block, the splat of a voxel,
// a pixel's alpha. Needs shading.glsl, phase_table.glsl and light.glsl before it (MakeSplat reads the
// Mie table with phase Mie). Must stay in step with the C++.
#ifndef CLOUDBENCH_SPLAT_GLSL
#define CLOUDBENCH_SPLAT_GLSL

// std430, member for member core/math/Splat.h SplatFrame (which says what each member holds).
struct SplatFrame {
    uvec3 grid;
    uint ranksPerChunk;
    uvec3 axes;
    uint voxelCount;
    uvec3 orderBase;
    uint unused0;
    uint boxTile;
    uint boxBand;
    uint boxTilesX;
    uint boxTilesY;
    uint width;
    uint height;
    uint tilesX;
    uint tilesY;
    vec3 eye;
    float nearPlane;
    vec3 forward;
    float focalPx;
    vec3 right;
    float qMin;
    vec3 up;
    float opacity;
    vec3 sun;
    float voxelSize;
    vec3 background;
    float splatDiameter;
    vec3 origin;
    float alpha;
    float maxPointSize;
    float unused1;
    float unused2;
    float unused3;
    LightGpu light;  // light.glsl
};

// std430, field for field core/math/Splat.h Splat.
struct Splat {
    float px, py, size, alphaScale;
    float r, g, b, pad;
    int x0, x1, y0, y1;
};

float SplatQ(float qPrev, float qCur, float alpha) {
    precise float qa = qPrev + alpha * (qCur - qPrev);
    return qa;
}

// std::isfinite.
bool SplatFinite(float v) { return !isnan(v) && !isinf(v); }

// The splat of voxel idx with q_alpha qa, transmittance t and the sky light's tSky; false when it makes none
// (also when px, py or size is not finite). Covered pixels are clamped before int().
bool MakeSplat(SplatFrame F, uvec3 idx, float qa, float t, float tSky, out Splat s) {
    s = Splat(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0, -1, 0, -1);
    if (!(qa > F.qMin)) return false;
    const float h = F.voxelSize;
    precise vec3 centre = vec3(F.origin.x + (float(idx.x) + 0.5) * h, F.origin.y + (float(idx.y) + 0.5) * h,
                               F.origin.z + (float(idx.z) + 0.5) * h);
    precise float dx = centre.x - F.eye.x, dy = centre.y - F.eye.y, dz = centre.z - F.eye.z;
    precise float x = dx * F.right.x + dy * F.right.y + dz * F.right.z;
    precise float y = dx * F.up.x + dy * F.up.y + dz * F.up.z;
    precise float depth = dx * F.forward.x + dy * F.forward.y + dz * F.forward.z;
    if (!(depth > F.nearPlane)) return false;
    const float focal = F.focalPx;
    precise float px = 0.5 * float(F.width) + x * focal / depth;
    precise float py = 0.5 * float(F.height) - y * focal / depth;
    precise float size = clamp(F.splatDiameter * focal / depth, 1.0, 255.0);
    if (!SplatFinite(px) || !SplatFinite(py) || !SplatFinite(size)) return false;
    precise float len = sqrt(dx * dx + dy * dy + dz * dz);
    precise float cosTheta = (F.sun.x * dx + F.sun.y * dy + F.sun.z * dz) / len;
    precise float light = SunGain(F.light, MakeSunPhases(F.light, cosTheta), t);
    s.px = px;
    s.py = py;
    s.size = size;
    s.alphaScale = qa * F.opacity;
    // The sample: the voxel centre in voxel units, seen along the unit direction from the eye.
    const vec3 at = vec3(float(idx.x) + 0.5, float(idx.y) + 0.5, float(idx.z) + 0.5);
    precise vec3 dir = vec3(dx / len, dy / len, dz / len);
    precise float skyGain = F.light.skyOn != 0u ? tSky * SkyPhase(F.light, dir) : 0.0;
    const vec3 colour = InScattered(F.light, LightSample(light, t, 1.0, at, dir, skyGain));
    s.r = colour.x;
    s.g = colour.y;
    s.b = colour.z;
    precise float halfSize = 0.5 * size;
    const float imageW = float(F.width), imageH = float(F.height);
    s.x0 = int(min(max(0.0, ceil(px - halfSize - 0.5)), imageW));
    s.x1 = int(max(min(imageW - 1.0, ceil(px + halfSize - 0.5) - 1.0), -1.0));
    s.y0 = int(min(max(0.0, ceil(py - halfSize - 0.5)), imageH));
    s.y1 = int(max(min(imageH - 1.0, ceil(py + halfSize - 0.5) - 1.0), -1.0));
    return true;
}

// (pixelCentre - centre) / size + 0.5, with pixelCentre = x + 0.5.
float SplatCoord(float pixelCentre, float centre, float size) {
    precise float a = (pixelCentre - centre) / size + 0.5;
    return a;
}

float SplatAlpha(float alphaScale, float a, float b) {
    precise float alpha = clamp(alphaScale * SplatKernel(a, b), 0.0, 1.0);
    return alpha;
}

#endif
