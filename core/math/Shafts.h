// Shafts of light (SPEC 18; seed 000, section 7.3.2 after Dobashi): the sun's
// light scattered toward the eye by a haze below the clouds, lit where the
// clouds let the sun through. docs/pipeline.md, "Shafts of light".
//
// The haze fills the slab 0 <= z <= nz/2 (voxel units: the ground plane up to
// the cloud layer's mid-height, where the density map D sits), infinite in x
// and y. S shells around the eye, at radii r_j = (j + 1/2) dr (j < S, dr =
// the frame's farthest reach / S), sample it: a pixel's ray adds, for each
// shell point p = o + r_j d inside the slab and within [near, far],
//   sun sigma dr P^(d.s) G(p) exp(-sigma r_j) f(d.s) view,
// with G(p) the ground shadow's form (SPEC 7) of D where the sun ray through p
// meets the mid-height, f the thesis's falloff near the sun (1 when off), and
// `view` the cloud layer's transmittance along the ray (the same form of D
// where the ray crosses the mid-height) when the eye is above the slab.
// Blended additively after the renderer, into any renderer's frame.
//
// Voxel units as in core/math/March.h. Scalar float code that
// core/math/shafts.glsl twins line by line; ShaftsFrame is the one block of
// constants every backend reads.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#include "core/math/Camera.h"
#include "core/math/March.h"
#include "core/math/Shading.h"

namespace cb {

// The most shells a scene may ask for: a pixel's loop is at most this long.
inline constexpr uint32_t kMaxShafts = 1024;

// The scene's shafts (section `lighting.shafts`; present: on).
struct ShaftsSettings {
    bool on = false;
    uint32_t shells = 16;      // S
    double extinction = 1e-4;  // sigma_air, per metre
    double g = 0.7;            // the haze's Henyey-Greenstein eccentricity
    double falloffDeg = 0;     // the thesis's falloff: no shafts farther than this from the sun; 0: off (f = 1)
};

// The constants of one frame's shafts, laid out alike by std140 and std430 (a
// scalar after a vec3 takes its fourth lane); core/math/shafts.glsl's
// ShaftsFrame twins it member for member.
struct alignas(16) ShaftsFrame {
    std::array<float, 3> eye;  // the eye in voxel units
    float focalPx;
    std::array<float, 3> forward;
    float nearPlane;  // metres
    std::array<float, 3> right;
    float farPlane;  // metres
    std::array<float, 3> up;
    float voxelSize;                   // h, metres
    std::array<float, 3> sunRadiance;  // colour * intensity
    float hazeTop;                     // nz / 2: the slab's top, the cloud layer's mid-height
    std::array<float, 3> sun;          // unit, toward the sun
    float extinction;                  // sigma_air h: per voxel edge
    float shellSpacing;                // dr, voxel edges
    float phaseG;                      // the haze's HG eccentricity
    float falloffCos;                  // cos of the falloff's width
    float falloffInvOneMinusCos;       // 1 / (1 - falloffCos); 0: no falloff (f = 1)
    float sunDepthPerD;                // sigma h / s_z: the optical depth per unit of D along the sun (SPEC 7)
    float sigmaH;                      // the clouds' sigma h, for the view's crossing
    float kappa;                       // the shadow forms' constants (ShadowParams)
    float coverage;
    float densityFactor;
    uint32_t form;    // ShadowForm
    uint32_t shells;  // S
    uint32_t tiling;  // 1: D repeats in x and y (grid.tiling)
    uint32_t gridX;   // nx, ny of D
    uint32_t gridY;
    uint32_t width;  // the image
    uint32_t height;
};
static_assert(sizeof(ShaftsFrame) == 10 * 16, "ShaftsFrame is ten 16-byte rows");

// A sun this close to the horizon (within about 6e-5 degrees) has set for the shafts: its ray's climb to the
// mid-height would be a million slab heights long, and GPUs may flush smaller values to 0.
inline constexpr float kShaftsMinSunZ = 1e-6f;

// The shadow form of SPEC 7 applied to a column sum d, with the optical depth per unit of D of the path at hand.
inline float ShaftsLayerForm(uint32_t form, float depthPerD, float kappa, float coverage, float densityFactor,
                             float d) {
    return form == uint32_t(ShadowForm::Wang) ? WangShadow(depthPerD, coverage, densityFactor, d)
                                              : GroundShadow(form == uint32_t(ShadowForm::Beer), depthPerD, kappa, d);
}

// D at the point (x, y) (voxel units): bilinear between the column centres (i + 0.5, j + 0.5); taps outside the
// grid read 0, or wrap with tiling. fetch(i, j) returns D of column (i, j).
template <class Fetch>
float ShaftsColumnAt(float x, float y, uint32_t nx, uint32_t ny, bool tiling, Fetch&& fetch) {
    const float u = x - 0.5f, v = y - 0.5f;
    const float fi = std::floor(u), fj = std::floor(v);
    const float fu = u - fi, fv = v - fj;
    if (tiling) {
        const float wi = fi - float(nx) * std::floor(fi / float(nx));
        const float wj = fj - float(ny) * std::floor(fj / float(ny));
        // Far from the origin the remainder loses its precision: the clamp keeps the tap inside.
        const uint32_t i0 = uint32_t(std::clamp(wi, 0.0f, float(nx - 1)));
        const uint32_t j0 = uint32_t(std::clamp(wj, 0.0f, float(ny - 1)));
        const uint32_t i1 = i0 + 1 == nx ? 0 : i0 + 1, j1 = j0 + 1 == ny ? 0 : j0 + 1;
        return Bilinear(fetch(i0, j0), fetch(i1, j0), fetch(i0, j1), fetch(i1, j1), fu, fv);
    }
    // Beyond one column outside, every tap is outside; the clamp keeps the conversion to int defined.
    const int32_t i0 = int32_t(std::clamp(fi, -2.0f, float(nx))), j0 = int32_t(std::clamp(fj, -2.0f, float(ny)));
    auto tap = [&](int32_t i, int32_t j) {
        return (i < 0 || j < 0 || i >= int32_t(nx) || j >= int32_t(ny)) ? 0.0f : fetch(uint32_t(i), uint32_t(j));
    };
    return Bilinear(tap(i0, j0), tap(i0 + 1, j0), tap(i0, j0 + 1), tap(i0 + 1, j0 + 1), fu, fv);
}

// The thesis's falloff near the sun: max(0, (cos - cos w) / (1 - cos w)); 1 when off (invOneMinusCos 0).
inline float ShaftsFalloff(float cosTheta, float falloffCos, float invOneMinusCos) {
    if (invOneMinusCos == 0.0f) return 1.0f;
    return std::max(0.0f, (cosTheta - falloffCos) * invOneMinusCos);
}

// The light the shells add to pixel (x, y) (RGB). fetch(i, j) returns D of column (i, j).
template <class Fetch>
Vec3 ShaftsPixel(const ShaftsFrame& b, uint32_t x, uint32_t y, Fetch&& fetch) {
    const Vec3 zero{0.0f, 0.0f, 0.0f};
    if (!(b.sun[2] > kShaftsMinSunZ)) return zero;  // no sun above the horizon: no shafts
    CameraFrame c;
    c.forward = b.forward;
    c.right = b.right;
    c.upVector = b.up;
    c.focalPx = b.focalPx;
    c.width = b.width;
    c.height = b.height;
    const PixelDirection p = PixelRayDirection(c, x, y);
    const Vec3 o = b.eye, d = p.dir;
    const float perDepth = 1.0f / (b.voxelSize * p.cosForward);
    float t0 = b.nearPlane * perDepth, t1 = b.farPlane * perDepth;
    const Vec3 slab{0.0f, 0.0f, b.hazeTop};
    ClipRayToSlab(o, d, slab, 2, t0, t1);
    if (!(t1 > t0)) return zero;
    const bool tiling = b.tiling != 0;
    auto columnAt = [&](float px, float py) { return ShaftsColumnAt(px, py, b.gridX, b.gridY, tiling, fetch); };
    // The eye above the slab looks at the haze through the cloud layer, where its ray crosses the mid-height.
    float view = 1.0f;
    if (o[2] > b.hazeTop && d[2] < 0.0f) {
        const float tc = (b.hazeTop - o[2]) / d[2];
        const float depthPerD = std::min(b.sigmaH / -d[2], std::numeric_limits<float>::max());
        view = ShaftsLayerForm(b.form, depthPerD, b.kappa, b.coverage, b.densityFactor,
                               columnAt(o[0] + d[0] * tc, o[1] + d[1] * tc));
    }
    // The shells inside [t0, t1]: r_j = (j + 0.5) dr.
    const float last = float(b.shells) - 1.0f;
    const float jFirst = std::clamp(std::ceil(t0 / b.shellSpacing - 0.5f), 0.0f, float(b.shells));
    const float jLast = std::clamp(std::floor(t1 / b.shellSpacing - 0.5f), -1.0f, last);
    float sum = 0.0f;
    for (uint32_t j = uint32_t(jFirst); float(j) <= jLast; ++j) {
        const float r = (float(j) + 0.5f) * b.shellSpacing;
        const float pz = o[2] + d[2] * r;
        const float climb = std::min((b.hazeTop - pz) / b.sun[2], 1e30f);  // finite: every tap then far outside
        const float column = columnAt(o[0] + d[0] * r + b.sun[0] * climb, o[1] + d[1] * r + b.sun[1] * climb);
        const float shadow = ShaftsLayerForm(b.form, b.sunDepthPerD, b.kappa, b.coverage, b.densityFactor, column);
        sum += shadow * ExpNonPositive(-b.extinction * r);
    }
    const float cosTheta = MarchDot(d, b.sun);
    const float scale = b.extinction * b.shellSpacing * HenyeyGreenstein(b.phaseG, cosTheta) *
                        ShaftsFalloff(cosTheta, b.falloffCos, b.falloffInvOneMinusCos) * view * sum;
    return {b.sunRadiance[0] * scale, b.sunRadiance[1] * scale, b.sunRadiance[2] * scale};
}

// The frame's block: the camera, the eye in voxel units, the shells spread evenly over the farthest reach of the
// frame (the far plane seen at a corner pixel's centre), the shadow form's constants (ShadowParams).
inline ShaftsFrame MakeShaftsFrame(const ShaftsSettings& s, const CameraFrame& c, const std::array<float, 3>& origin,
                                   float voxelSize, uint32_t nx, uint32_t ny, uint32_t nz, bool tiling, const Vec3& sun,
                                   const Vec3& sunRadiance, ShadowForm form, float sigma, float kappa, float coverage,
                                   float densityFactor) {
    ShaftsFrame b{};
    const std::array<float, 3> eye{(c.eye[0] - origin[0]) / voxelSize, (c.eye[1] - origin[1]) / voxelSize,
                                   (c.eye[2] - origin[2]) / voxelSize};
    SetCameraMembers(b, c, eye, voxelSize);
    b.sunRadiance = sunRadiance;
    b.hazeTop = 0.5f * float(nz);
    b.sun = sun;
    b.extinction = float(s.extinction * voxelSize);
    const float reach = c.farPlane / (voxelSize * PixelRayDirection(c, 0, 0).cosForward);
    b.shellSpacing = reach / float(s.shells);
    b.phaseG = float(s.g);
    if (s.falloffDeg > 0) {
        const double cosW = std::cos(s.falloffDeg * 3.14159265358979323846 / 180.0);
        b.falloffCos = float(cosW);
        b.falloffInvOneMinusCos = float(1.0 / (1.0 - cosW));
    }
    const float sigmaH = sigma * voxelSize;
    b.sunDepthPerD = sun[2] > kShaftsMinSunZ ? std::min(sigmaH / sun[2], std::numeric_limits<float>::max()) : 0.0f;
    b.sigmaH = sigmaH;
    b.kappa = kappa;
    b.coverage = coverage;
    b.densityFactor = densityFactor;
    b.form = uint32_t(form);
    b.shells = s.shells;
    b.tiling = tiling ? 1u : 0u;
    b.gridX = nx;
    b.gridY = ny;
    return b;
}

}  // namespace cb
