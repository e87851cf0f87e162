// GLSL twin of core/math/Shafts.h: shafts of light, the haze below the clouds
// lit through the density map, sampled by S shells around the eye
// (docs/pipeline.md, "Shafts of light"). The same operations in the same order
// as the C++, `precise` where the CPU (built with -ffp-contract=off) rounds
// each product.
//
// Include after shading.glsl and march.glsl. The including shader DEFINES
//   float ShaftsFetchD(uint i, uint j);  // D of column (i, j), 0 <= i < nx, 0 <= j < ny
#ifndef CLOUDBENCH_SHAFTS_GLSL
#define CLOUDBENCH_SHAFTS_GLSL

// core/math/Shafts.h ShaftsFrame, member for member.
struct ShaftsFrame {
    vec3 eye;  // voxel units
    float focalPx;
    vec3 forward;
    float nearPlane;  // metres
    vec3 right;
    float farPlane;  // metres
    vec3 up;
    float voxelSize;  // h, metres
    vec3 sunRadiance;
    float hazeTop;  // nz / 2
    vec3 sun;       // unit, toward the sun
    float extinction;  // sigma_air h
    float shellSpacing;
    float phaseG;
    float falloffCos;
    float falloffInvOneMinusCos;  // 0: no falloff
    float sunDepthPerD;           // sigma h / s_z
    float sigmaH;
    float kappa;
    float coverage;
    float densityFactor;
    uint form;  // ShadowForm: 0 beer, 1 thesis, 2 wang
    uint shells;
    uint tiling;
    uint gridX;
    uint gridY;
    uint width;
    uint height;
};

const float kShaftsMinSunZ = 1e-6;

float ShaftsFetchD(uint i, uint j);

// core/math/Shafts.h ShaftsLayerForm.
float ShaftsLayerForm(uint form, float depthPerD, float kappa, float coverage, float densityFactor, float d) {
    return form == 2u ? WangShadow(depthPerD, coverage, densityFactor, d)
                      : GroundShadow(form == 0u ? 1u : 0u, depthPerD, kappa, d);
}

float ShaftsTapD(int i, int j, uint nx, uint ny) {
    return (i < 0 || j < 0 || i >= int(nx) || j >= int(ny)) ? 0.0 : ShaftsFetchD(uint(i), uint(j));
}

// core/math/Shafts.h ShaftsColumnAt with the fetch ShaftsFetchD.
float ShaftsColumnAt(float x, float y, uint nx, uint ny, bool tiling) {
    precise float u = x - 0.5;
    precise float v = y - 0.5;
    const float fi = floor(u), fj = floor(v);
    precise float fu = u - fi;
    precise float fv = v - fj;
    if (tiling) {
        precise float wi = fi - float(nx) * floor(fi / float(nx));
        precise float wj = fj - float(ny) * floor(fj / float(ny));
        const uint i0 = uint(clamp(wi, 0.0, float(nx - 1u))), j0 = uint(clamp(wj, 0.0, float(ny - 1u)));
        const uint i1 = i0 + 1u == nx ? 0u : i0 + 1u, j1 = j0 + 1u == ny ? 0u : j0 + 1u;
        return Bilinear(ShaftsFetchD(i0, j0), ShaftsFetchD(i1, j0), ShaftsFetchD(i0, j1), ShaftsFetchD(i1, j1), fu, fv);
    }
    const int i0 = int(clamp(fi, -2.0, float(nx))), j0 = int(clamp(fj, -2.0, float(ny)));
    return Bilinear(ShaftsTapD(i0, j0, nx, ny), ShaftsTapD(i0 + 1, j0, nx, ny), ShaftsTapD(i0, j0 + 1, nx, ny),
                    ShaftsTapD(i0 + 1, j0 + 1, nx, ny), fu, fv);
}

// core/math/Shafts.h ShaftsFalloff.
float ShaftsFalloff(float cosTheta, float falloffCos, float invOneMinusCos) {
    if (invOneMinusCos == 0.0) return 1.0;
    precise float f = (cosTheta - falloffCos) * invOneMinusCos;
    return max(0.0, f);
}

// core/math/Shafts.h ShaftsPixel: the light the shells add to pixel (x, y).
vec3 ShaftsPixel(ShaftsFrame b, uint x, uint y) {
    if (!(b.sun.z > kShaftsMinSunZ)) return vec3(0.0);
    float cosForward;
    const vec3 d = PixelRayDirection(b.forward, b.right, b.up, b.focalPx, uvec2(b.width, b.height), x, y, cosForward);
    const vec3 o = b.eye;
    precise float perDepth = 1.0 / (b.voxelSize * cosForward);
    precise float t0 = b.nearPlane * perDepth;
    precise float t1 = b.farPlane * perDepth;
    ClipRayToSlab(o, d, vec3(0.0, 0.0, b.hazeTop), 2, t0, t1);
    if (!(t1 > t0)) return vec3(0.0);
    const bool tiling = b.tiling != 0u;
    float view = 1.0;
    if (o.z > b.hazeTop && d.z < 0.0) {
        precise float tc = (b.hazeTop - o.z) / d.z;
        precise float depthPerD = min(b.sigmaH / -d.z, 3.402823466e38);
        precise float cx = o.x + d.x * tc;
        precise float cy = o.y + d.y * tc;
        view = ShaftsLayerForm(b.form, depthPerD, b.kappa, b.coverage, b.densityFactor,
                               ShaftsColumnAt(cx, cy, b.gridX, b.gridY, tiling));
    }
    const float last = float(b.shells) - 1.0;
    precise float firstShell = t0 / b.shellSpacing - 0.5;
    precise float lastShell = t1 / b.shellSpacing - 0.5;
    const float jFirst = clamp(ceil(firstShell), 0.0, float(b.shells));
    const float jLast = clamp(floor(lastShell), -1.0, last);
    precise float sum = 0.0;
    for (uint j = uint(jFirst); float(j) <= jLast; ++j) {
        precise float r = (float(j) + 0.5) * b.shellSpacing;
        precise float pz = o.z + d.z * r;
        precise float climb = min((b.hazeTop - pz) / b.sun.z, 1e30);
        precise float px = o.x + d.x * r + b.sun.x * climb;
        precise float py = o.y + d.y * r + b.sun.y * climb;
        const float column = ShaftsColumnAt(px, py, b.gridX, b.gridY, tiling);
        const float shadow = ShaftsLayerForm(b.form, b.sunDepthPerD, b.kappa, b.coverage, b.densityFactor, column);
        sum += shadow * ExpNonPositive(-b.extinction * r);
    }
    const float cosTheta = MarchDot(d, b.sun);
    precise float scale =
        b.extinction * b.shellSpacing * HenyeyGreenstein(b.phaseG, cosTheta) *
        ShaftsFalloff(cosTheta, b.falloffCos, b.falloffInvOneMinusCos) * view * sum;
    precise vec3 light = vec3(b.sunRadiance.x * scale, b.sunRadiance.y * scale, b.sunRadiance.z * scale);
    return light;
}

#endif
