#include "harness/StageParams.h"

#include "core/Random.h"

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

DensityParams MakeDensityParams(const Scene& sc) { return {sc.density.tile, sc.density.band}; }

ShadeParams MakeShadeParams(const Scene& sc) {
    ShadeParams p;
    p.sun = sc.sun.Direction();
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

ShadowParams MakeShadowParams(const Scene& sc) {
    ShadowParams p;
    p.sun = sc.sun.Direction();
    p.form = sc.shadow.form;
    p.sigma = float(sc.shade.sigma);
    p.voxelSize = float(sc.grid.voxelSize);
    p.kappa = float(sc.shadow.kappa);
    p.nz = sc.grid.size.nz;
    return p;
}

NoiseParams MakeNoiseParams(const Scene& sc, uint32_t step) { return {step, &sc.noise, sc.grid.size}; }

SplatParams MakeSplatParams(const Scene& sc, const CameraSettings& camera) {
    SplatParams p;
    p.camera = MakeCameraFrame(camera, sc.render.width, sc.render.height);
    p.sun = sc.sun.Direction();
    p.sunRadiance = sc.sun.Radiance();
    for (int c = 0; c < 3; ++c) {
        p.ambient[c] = float(sc.lighting.ambient[c]);
        p.background[c] = float(sc.lighting.background[c]);
    }
    p.phase = sc.phase;
    p.qMin = float(sc.splat.qMin);
    p.splatDiameter = float(sc.splat.splatScale * sc.grid.voxelSize);
    p.opacity = float(sc.splat.opacity);
    p.alpha = float(sc.render.alpha);
    p.origin = {float(sc.grid.origin[0]), float(sc.grid.origin[1]), float(sc.grid.origin[2])};
    p.voxelSize = float(sc.grid.voxelSize);
    p.culling = sc.splat.culling;
    p.skipping = sc.splat.skipping;
    p.tile = sc.density.tile;
    p.band = sc.density.band;
    return p;
}

}  // namespace cb
