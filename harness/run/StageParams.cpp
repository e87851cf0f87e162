#include "harness/run/StageParams.h"

#include "core/math/Random.h"

namespace cb {

CaInitParams MakeCaInitParams(const Scene& sc) {
    return {sc.ca.seed, QuantizeProbability(sc.ca.hum0), QuantizeProbability(sc.ca.act0)};
}

CaStepParams MakeCaStepParams(const Scene& sc, uint32_t step) {
    CaStepParams p;
    p.seed = sc.ca.seed;
    p.step = step;
    p.qExt = QuantizeProbability(sc.ca.pExt);
    p.qHum = QuantizeProbability(sc.ca.pHum);
    p.qAct = QuantizeProbability(sc.ca.pAct);
    return p;
}

DensityParams MakeDensityParams(const Scene& sc) {
    DensityParams p;
    p.tile = sc.density.tile;
    p.band = sc.density.band;
    return p;
}

ShadeParams MakeShadeParams(const Scene& sc, uint32_t step) {
    ShadeParams p;
    p.sun = sc.sun.DirectionAt(step);
    p.attenuation = sc.shade.attenuation;
    p.sigma = float(sc.shade.sigma);
    p.voxelSize = float(sc.grid.voxelSize);
    p.thesisAr = float(sc.shade.thesisAr);
    p.filter = sc.shade.filter;
    p.resolution = sc.shade.resolution;
    p.storage = sc.shade.storage;
    p.scattering = sc.shade.scattering;
    p.albedo = float(sc.shade.albedo);
    p.solidAngle = float(sc.shade.solidAngle);
    p.phase = sc.phase;
    return p;
}

ShadowParams MakeShadowParams(const Scene& sc, uint32_t step) {
    ShadowParams p;
    p.sun = sc.sun.DirectionAt(step);
    p.form = sc.shadow.form;
    p.sigma = float(sc.shade.sigma);
    p.voxelSize = float(sc.grid.voxelSize);
    p.kappa = float(sc.shadow.kappa);
    p.coverage = float(sc.shadow.coverage);
    p.densityFactor = float(sc.shadow.densityFactor);
    p.nz = sc.grid.size.nz;
    return p;
}

NoiseParams MakeNoiseParams(const Scene& sc, uint32_t step) { return {step, &sc.noise, sc.grid.size}; }

GroundParams MakeGroundParams(const Scene& sc) {
    const auto& a = sc.render.ground.albedo;
    return {sc.render.ground.on, {float(a[0]), float(a[1]), float(a[2])}};
}

SplatParams MakeSplatParams(const Scene& sc, const CameraSettings& camera, uint32_t step, uint32_t frame,
                            uint32_t frames) {
    SplatParams p;
    p.camera = MakeCameraFrame(camera, sc.render.width, sc.render.height);
    p.sun = sc.sun.DirectionAt(step);
    p.sunRadiance = sc.sun.Radiance();
    p.ambient = sc.lighting.Ambient();
    p.background = sc.lighting.Background();
    p.phase = sc.phase;
    p.qMin = float(sc.splat.qMin);
    p.splatDiameter = float(sc.splat.splatScale * sc.grid.voxelSize);
    p.opacity = float(sc.splat.opacity);
    p.alpha = sc.render.FrameAlpha(frame, frames);
    p.origin = {float(sc.grid.origin[0]), float(sc.grid.origin[1]), float(sc.grid.origin[2])};
    p.voxelSize = float(sc.grid.voxelSize);
    p.culling = sc.splat.culling;
    p.skipping = sc.splat.skipping;
    p.tile = sc.density.tile;
    p.band = sc.density.band;
    p.ground = MakeGroundParams(sc);
    return p;
}

MarchParams MakeMarchParams(const Scene& sc, const CameraSettings& camera, uint32_t step, uint32_t frame,
                            uint32_t frames) {
    MarchParams p;
    p.camera = MakeCameraFrame(camera, sc.render.width, sc.render.height);
    const float h = float(sc.grid.voxelSize);
    p.origin = {float(sc.grid.origin[0]), float(sc.grid.origin[1]), float(sc.grid.origin[2])};
    MarchSetup& s = p.setup;
    s.size = {float(sc.grid.size.nx), float(sc.grid.size.ny), float(sc.grid.size.nz)};
    s.voxelSize = h;
    s.step = float(sc.march.step);
    s.adaptive = sc.march.adaptive;
    s.kappa = float(sc.march.kappa);
    s.adaptiveStart = float(sc.march.adaptiveStart);
    s.sigmaH = MarchOpticalDepthPerVoxel(float(sc.shade.sigma), h);
    s.epsilon = float(sc.march.epsilon);
    s.sun = sc.sun.DirectionAt(step);
    s.sunRadiance = sc.sun.Radiance();
    s.ambient = sc.lighting.Ambient();
    s.background = sc.lighting.Background();
    s.phase = sc.phase;
    s.powder = sc.march.powder;
    s.powderC = float(sc.march.powderC);
    const LightningSettings& l = sc.lightning;
    s.point.on = l.OnAt(step);
    for (int c = 0; c < 3; ++c) {
        s.point.position[c] = float((l.position[c] - sc.grid.origin[c]) / sc.grid.voxelSize);
        s.point.radiance[c] = float(l.color[c] * l.intensity);
    }
    s.point.minDistance2 = float(l.radius * l.radius);
    p.alpha = sc.render.FrameAlpha(frame, frames);
    p.light = sc.march.light;
    p.lightSteps = sc.march.lightSteps;
    p.jitter = sc.march.jitter;
    p.seed = sc.ca.seed;
    p.frame = step;
    p.skipping = sc.march.skipping;
    p.brick = sc.march.brick;
    p.ground = MakeGroundParams(sc);
    return p;
}

}  // namespace cb
