// The ray marcher's test parameters, shared by MarchTest (the CPU kernel) and
// the per-backend RenderMarch tests: a plain kernel setup and a camera's
// MarchParams over a grid in voxel units (h = 1 m).
#pragma once

#include <array>

#include "core/math/Camera.h"
#include "core/math/Shading.h"
#include "core/pipeline/Backend.h"

namespace cb::test {

// Phase none, the sun overhead, no early termination (epsilon 0), step 1/2.
inline MarchSetup PlainSetup(Vec3 size, float sigmaH) {
    MarchSetup s;
    s.size = size;
    s.voxelSize = s.light.voxelSize = 1;
    s.step = 0.5f;
    s.sigmaH = sigmaH;
    s.epsilon = 0;
    s.sun = {0, 0, 1};
    s.light.sunRadiance = {1.0f, 0.9f, 0.8f};
    s.light.ambient = {0.2f, 0.25f, 0.3f};
    s.background = {0.4f, 0.6f, 0.9f};
    s.light.phase.kind = PhaseKind::None;
    return s;
}

// A camera from eye to target (fov 50, near 0.01, far 1e5), the box of grid e,
// HG 0.6, the sun at (0.7, 0.4) rad, alpha 1/2; otherwise PlainSetup.
inline MarchParams CameraParams(const Extent3& e, std::array<double, 3> eye, std::array<double, 3> target, uint32_t w,
                               uint32_t h, float sigma = 0.05f) {
    CameraSettings cam;
    cam.eye = eye;
    cam.target = target;
    cam.fovDeg = 50;
    cam.nearPlane = 0.01;
    cam.farPlane = 1e5;
    MarchParams p;
    p.camera = MakeCameraFrame(cam, w, h);
    p.setup = PlainSetup({float(e.nx), float(e.ny), float(e.nz)}, sigma);
    p.setup.light.phase = {PhaseKind::HenyeyGreenstein, 0.6f};
    p.setup.sun = SunDirection(0.7, 0.4);
    p.origin = {0, 0, 0};
    p.alpha = 0.5f;
    return p;
}

// render_layers' parameters over grid e seen by m's camera (h = 1 m, origin 0, alpha 0.3): `count` layers at
// spacing nz / count, beer opacity with sigma h 0.3 and l_max nz, an extent past every fragment, m's sun,
// lighting and phase.
inline LayersParams LayersFromCamera(const MarchParams& m, const Extent3& e, uint32_t count, bool tiling) {
    LayersParams p;
    p.camera = m.camera;
    p.alpha = 0.3f;
    LayersSetup& s = p.setup;
    for (int a = 0; a < 3; ++a) s.eye[a] = m.camera.eye[a];
    s.size = m.setup.size;
    s.invSize = {1.0f / s.size[0], 1.0f / s.size[1], 1.0f / s.size[2]};
    s.voxelSize = 1;
    s.count = count;
    s.spacing = float(double(e.nz) / count);
    s.outer2 = 1e10f;
    s.maxLength = float(e.nz);
    s.sigmaH = 0.3f;
    s.tiling = tiling;
    s.sun = m.setup.sun;
    s.light.sunRadiance = m.setup.light.sunRadiance;
    s.light.ambient = m.setup.light.ambient;
    s.background = m.setup.background;
    s.light.phase = m.setup.light.phase;
    return p;
}

}  // namespace cb::test
