#version 450
// The GLSL twins of core/math, one function per `fn` (tests/GlslTwinTest.cpp
// lists them): element n reads 16 words at in[16 n] and writes 16 at out[16 n];
// floats travel as their bits.
#extension GL_GOOGLE_include_directive : require
#include "random.glsl"
#include "rules.glsl"
#include "shading.glsl"
#include "phase_table.glsl"
#include "light.glsl"
#include "automaton.glsl"
#include "splat.glsl"
#include "noise_words.glsl"
#include "noise.glsl"
#include "march.glsl"
#include "ground.glsl"
#include "layers.glsl"
#include "shafts.glsl"

// The functions' numbers by name (kTwinLowBias32, ...), from the list the C++ reads too.
#define CB_TWIN_FN(name, number) const uint kTwin##name = number;
#include "twin_fns.h"
#undef CB_TWIN_FN

layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer In { uint inWords[]; };
layout(std430, binding = 1) writeonly buffer Out { uint outWords[]; };
layout(std430, binding = 2) readonly buffer Frame { SplatFrame frame; };
layout(std430, binding = 3) readonly buffer March { MarchGpu march; };
layout(std430, binding = 4) readonly buffer MieTable { float mieTable[]; };  // kMieCloudTable
layout(std430, binding = 5) readonly buffer Layers { LayersGpu layers; };
layout(std430, binding = 6) readonly buffer Billboards { LayersBillboard twinBillboards[]; };  // LOD0's list
layout(push_constant) uniform Params { uint fn, count; } pc;

// march.glsl's volume: a hash of the padded index (tests/GlslTwinTest.cpp TwinPaddedQT);
// bricks: every third empty; the phase table: kMieCloudTable.
vec2 MarchFetchQT(uint i) {
    return vec2(float(LowBias32(i) >> 8u) * (1.0 / 16777216.0),
                float(LowBias32(i ^ 0x9E3779B9u) >> 8u) * (1.0 / 16777216.0));
}
// march.glsl's T_sky: a third hash of the padded index (tests/GlslTwinHarness.h TwinPaddedSkyT).
float MarchFetchSkyT(uint i) { return float(LowBias32(i ^ 0x2545F491u) >> 8u) * (1.0 / 16777216.0); }
bool MarchBrickEmpty(uint brick) { return brick % 3u == 0u; }
// ground.glsl's G: a hash of the cell (tests/GlslTwinMarchCases.cpp TwinGroundG).
float GroundFetchG(uint i, uint j) { return float(LowBias32(i + 4096u * j) >> 8u) * (1.0 / 16777216.0); }
float PhaseTableValue(uint i) { return mieTable[i]; }
// shafts.glsl's D: a hash of the column (tests/GlslTwinMarchCases.cpp TwinShaftsD).
float ShaftsFetchD(uint i, uint j) { return float(LowBias32(i * 7919u + 65537u * j) >> 8u) * (1.0 / 1048576.0); }
// layers.glsl's modulation map: a hash of the column index (tests/GlslTwinHarness.h TwinLayersMap).
float LayersMapValue(uint i) { return float(LowBias32(i ^ 0x51ED27u) >> 8u) * (1.0 / 16777216.0); }
// layers.glsl's billboards: the bound list (GlslTwin::Run's `billboards`).
LayersBillboard LayersBillboardAt(uint i) { return twinBillboards[i]; }

LightGpu ZeroLight() {
    return LightGpu(vec3(0.0), 0u, vec3(0.0), 0.0, vec3(0.0), 0.0, vec3(0.0), 0u, 0.0, 0.0, 0u, 0u, 0.0, 0.0, 0.0, 0u,
                    vec3(0.0), 0u, 0.0,
                    0.0, 0u, 0u, vec4[4](vec4(0.0), vec4(0.0), vec4(0.0), vec4(0.0)), vec3(0.0, 0.0, 1.0), 0u, 0.0,
                    0.0, 0.0, 0.0, vec3(0.0), 0u, vec3(0.0, 0.0, 1.0), 0u, 1u, 1.0, 1.0, 1.0);
}

MarchGpu ZeroMarch() {
    return MarchGpu(vec3(0.0), 0.0, vec3(0.0), 0.0, vec3(0.0), 0.0, vec3(0.0), 0.0, vec3(0.0), 0.0, 0.0, 0.0, 0.0, 0.0,
                    vec3(0.0), 0.0, vec3(0.0), 0u, 0u, 0u, 0u, 0u, 0u, 0u, 0u, 0u, uvec3(0u), 0u, vec3(0.0), 0u,
                    ZeroLight());
}

// noise.glsl's tables: one permutation, i -> (167 i + 13) mod 256 (tests/GlslTwinCases.cpp kTwinPerm).
uint NoiseWord(uint index) { return ((index & 255u) * 167u + 13u) & 255u; }

uint base;
uint U(uint k) { return inWords[base + k]; }
float F(uint k) { return uintBitsToFloat(inWords[base + k]); }
int I(uint k) { return int(inWords[base + k]); }
void PutU(uint k, uint v) { outWords[base + k] = v; }
void PutF(uint k, float v) { outWords[base + k] = floatBitsToUint(v); }
void PutI(uint k, int v) { outWords[base + k] = uint(v); }

void main() {
    const uint n = gl_GlobalInvocationID.x;
    if (n >= pc.count) return;
    base = 16u * n;
    switch (pc.fn) {
        case kTwinLowBias32: PutU(0u, LowBias32(U(0u))); break;
        case kTwinStreamKey: PutU(0u, StreamKey(U(0u), U(1u), U(2u))); break;
        case kTwinRand24FromKey: PutU(0u, Rand24FromKey(U(0u), U(1u))); break;
        case kTwinRegionEventFires: PutU(0u, RegionEventFires(U(0u), U(1u), U(2u)) ? 1u : 0u); break;
        case kTwinEllipsoidWeight: PutF(0u, EllipsoidWeight(vec3(F(0u), F(1u), F(2u)), vec3(F(3u), F(4u), F(5u)), F(6u), F(7u),
                                          vec3(F(8u), F(9u), F(10u)))); break;
        case kTwinQuantizeRegion: PutU(0u, QuantizeRegion(F(0u))); break;
        case kTwinSmoothWeight: PutI(0u, SmoothWeight(I(0u), I(1u))); break;
        case kTwinExpNonPositive: PutF(0u, ExpNonPositive(F(0u))); break;
        case kTwinRoundToHalf: PutF(0u, RoundToHalf(F(0u))); break;
        case kTwinRoundToUnorm8: PutF(0u, RoundToUnorm8(F(0u))); break;
        case kTwinRoundToStorage: PutF(0u, RoundToStorage(U(0u), F(1u))); break;
        case kTwinLerp: PutF(0u, Lerp(F(0u), F(1u), F(2u))); break;
        case kTwinBilinear: PutF(0u, Bilinear(F(0u), F(1u), F(2u), F(3u), F(4u), F(5u))); break;
        case kTwinPhaseValue: PutF(0u, PhaseValue(U(0u), F(1u), F(2u))); break;
        case kTwinDualLobePhase: PutF(0u, DualLobePhase(F(0u), F(1u), F(2u), F(3u))); break;
        case kTwinSplatKernel: PutF(0u, SplatKernel(F(0u), F(1u))); break;
        case kTwinSliceFactor: PutF(0u, SliceFactor(U(0u), F(1u), F(2u), F(3u), F(4u))); break;
        case kTwinStoreTransmittance: PutF(0u, StoreTransmittance(U(0u), F(1u), F(2u))); break;
        case kTwinGroundShadow: PutF(0u, GroundShadow(U(0u), F(1u), F(2u), F(3u))); break;
        case kTwinWangShadow: PutF(0u, WangShadow(F(0u), F(1u), F(2u), F(3u))); break;
        case kTwinGroundHit: {
            vec2 p;
            const bool hit = GroundHit(vec3(F(0u), F(1u), F(2u)), vec3(F(3u), F(4u), F(5u)), F(6u), F(7u), p);
            PutU(0u, hit ? 1u : 0u);
            PutF(1u, hit ? p.x : 0.0);
            PutF(2u, hit ? p.y : 0.0);
            break;
        }
        case kTwinGroundShadowAt: PutF(0u, GroundShadowAt(F(0u), F(1u), U(2u), U(3u))); break;
        case kTwinGroundChannel: PutF(0u, GroundChannel(F(0u), F(1u), F(2u), F(3u), F(4u))); break;
        case kTwinShaftsColumnAt: PutF(0u, ShaftsColumnAt(F(0u), F(1u), U(2u), U(3u), U(4u) != 0u)); break;
        case kTwinShaftsLayerForm: PutF(0u, ShaftsLayerForm(U(0u), F(1u), F(2u), F(3u), F(4u), F(5u))); break;
        case kTwinShaftsFalloff: PutF(0u, ShaftsFalloff(F(0u), F(1u), F(2u))); break;
        case kTwinUpsampleTap: {
            int i0, i1;
            float w;
            UpsampleTap(I(0u), I(1u), I(2u), i0, i1, w);
            PutI(0u, i0);
            PutI(1u, i1);
            PutF(2u, w);
            break;
        }
        case kTwinCaRowNeighbours: PutU(0u, CaRowNeighbours(U(0u), U(1u), U(2u))); break;
        case kTwinCaGrowth: {
            const uvec3 s = CaGrowth(uvec3(U(0u), U(1u), U(2u)), U(3u));
            PutU(0u, s.x);
            PutU(1u, s.y);
            PutU(2u, s.z);
            break;
        }
        case kTwinCaVoxelEvents: {
            const CaEvents e = CaEvents(U(5u), U(6u), U(7u), U(8u), U(9u), U(10u));
            const uvec3 s = CaVoxelEvents(uvec3(U(0u), U(1u), U(2u)), U(3u), U(4u), e);
            PutU(0u, s.x);
            PutU(1u, s.y);
            PutU(2u, s.z);
            break;
        }
        case kTwinCaInitialVoxel: {
            const uvec3 s = CaInitialVoxel(U(0u), U(1u), U(2u), U(3u), U(4u));
            PutU(0u, s.x);
            PutU(1u, s.y);
            PutU(2u, s.z);
            break;
        }
        case kTwinMakeCaEvents: {
            const CaEvents e = MakeCaEvents(U(0u), U(1u), U(2u), U(3u), U(4u));
            PutU(0u, e.keyExt);
            PutU(1u, e.keyHum);
            PutU(2u, e.keyAct);
            PutU(3u, e.qExt);
            PutU(4u, e.qHum);
            PutU(5u, e.qAct);
            break;
        }
        case kTwinSplatQ: PutF(0u, SplatQ(F(0u), F(1u), F(2u))); break;
        case kTwinSplatCoord: PutF(0u, SplatCoord(F(0u), F(1u), F(2u))); break;
        case kTwinSplatAlpha: PutF(0u, SplatAlpha(F(0u), F(1u), F(2u))); break;
        case kTwinNoisePerlin: PutF(0u, NoisePerlin(0u, F(0u), F(1u), F(2u), ivec3(I(3u), I(4u), I(5u)))); break;
        case kTwinNoiseSimplex: PutF(0u, NoiseSimplex(0u, F(0u), F(1u), F(2u), ivec3(I(3u), I(4u), I(5u)))); break;
        case kTwinNoiseWorley: PutF(0u, NoiseWorley(U(6u), F(0u), F(1u), F(2u), ivec3(I(3u), I(4u), I(5u)))); break;
        case kTwinNoiseFbm: {
            const float sum = NoiseFbm(U(6u), 0u, U(7u), U(8u), F(9u), U(10u), U(11u) != 0u, F(0u), F(1u), F(2u),
                                       ivec3(I(3u), I(4u), I(5u)));
            PutF(0u, sum);
            PutF(1u, NoiseFbm01FromSum(U(6u), U(8u), F(9u), U(11u) != 0u, sum));
            break;
        }
        case kTwinNoiseForming:
            PutF(0u, NoiseThreshold(F(0u), F(1u)));
            PutF(1u, CoverageModulate(F(0u), F(2u), F(3u), F(4u)));
            PutF(2u, NoiseErode(F(0u), F(5u), F(6u)));
            PutI(3u, NoiseWrapIndex(I(7u), I(8u)));
            PutF(4u, NoiseRound(F(9u)));
            break;
        case kTwinNoiseHeightAndTower:
            PutF(0u, NoiseHeightDistribution(F(0u), F(1u), F(2u)));
            PutF(1u, NoiseTower(vec3(F(3u), F(4u), F(5u)), vec3(F(6u), F(7u), F(8u)), F(9u), F(10u), F(11u), F(12u),
                                F(13u), F(14u)));
            break;
        // ---- march.glsl ----
        case kTwinArcCos: PutF(0u, ArcCos(F(0u))); break;
        case kTwinSamplePhaseTable: PutF(0u, SamplePhaseTable(F(0u), U(1u), F(2u))); break;
        case kTwinLightPhase: {
            MarchGpu m = ZeroMarch();
            m.light.phaseKind = U(0u);
            m.light.phaseG = F(1u);
            m.light.phaseGForward = F(5u);
            m.light.phaseGBackward = F(6u);
            m.light.phaseBlend = F(7u);
            m.light.mieIndexPerRadian = F(3u);
            m.light.mieCount = U(4u);
            PutF(0u, LightPhase(m.light, F(2u)));
            break;
        }
        case kTwinClipRayToBox: {
            float tMin = F(9u), tMax = F(10u);
            ClipRayToBox(vec3(F(0u), F(1u), F(2u)), vec3(F(3u), F(4u), F(5u)), vec3(F(6u), F(7u), F(8u)), tMin, tMax);
            PutF(0u, tMin);
            PutF(1u, tMax);
            float zMin = F(9u), zMax = F(10u);
            ClipRayToVolume(vec3(F(0u), F(1u), F(2u)), vec3(F(3u), F(4u), F(5u)), vec3(F(6u), F(7u), F(8u)), true, zMin,
                            zMax);
            PutF(2u, zMin);
            PutF(3u, zMax);
            break;
        }
        case kTwinMarchBrickAt: {
            MarchGpu m = ZeroMarch();
            m.size = vec3(F(3u), F(4u), F(5u));
            m.invSize = vec3(F(6u), F(7u), F(8u));
            m.bricks = uvec3(U(9u), U(10u), U(11u));
            m.flags = U(14u) != 0u ? kMarchTiling : 0u;
            const MarchBrickCell cell = MarchBrickAt(m, F(13u), vec3(F(0u), F(1u), F(2u)));
            vec3 lo = vec3(0.0), hi = vec3(0.0);
            if (cell.inside) MarchBrickBox(m, cell, F(12u), lo, hi);
            PutU(0u, cell.inside ? 1u : 0u);
            PutU(1u, cell.index);
            PutF(2u, lo.x);
            PutF(3u, lo.y);
            PutF(4u, lo.z);
            PutF(5u, hi.x);
            PutF(6u, hi.y);
            PutF(7u, hi.z);
            break;
        }
        case kTwinMarchStepAt: {
            MarchGpu m = ZeroMarch();
            m.baseStep = F(0u);
            m.kappa = F(1u);
            m.adaptiveStart = F(2u);
            m.flags = U(3u) != 0u ? kMarchAdaptive : 0u;
            PutF(0u, MarchStepAt(m, F(4u)));
            break;
        }
        case kTwinMarchAdaptiveLanding: {
            MarchGpu m = ZeroMarch();
            m.baseStep = F(0u);
            m.kappa = F(1u);
            m.adaptiveStart = F(2u);
            m.flags = kMarchAdaptive;
            PutF(0u, MarchAdaptiveLanding(m, F(3u), F(4u), F(5u), F(6u)));
            break;
        }
        case kTwinMarchJitter: PutF(0u, MarchJitter(U(0u), U(1u), U(2u))); break;
        case kTwinRayExitFromBox: {
            const vec3 inv = InverseDirection(vec3(F(3u), F(4u), F(5u)));
            PutF(0u, RayExitFromBox(vec3(F(0u), F(1u), F(2u)), inv, vec3(F(6u), F(7u), F(8u)),
                                    vec3(F(9u), F(10u), F(11u)), F(12u)));
            PutF(1u, inv.x);
            PutF(2u, inv.y);
            PutF(3u, inv.z);
            break;
        }
        case kTwinPowderTerm: PutF(0u, PowderTerm(F(0u), F(1u))); break;
        case kTwinMarchKernelFormulas:
            PutF(0u, SegmentTransmittance(F(0u), F(1u), F(2u)));
            PutF(1u, PointLightFalloff(F(3u), F(4u)));
            PutF(2u, MarchNextUp(F(5u)));
            break;
        // With the bound MarchGpu (tests/GlslTwinTest.cpp MarchFrameTwin).
        case kTwinMakePixelRay: {
            const MarchRayGeometry r = MakePixelRay(march, U(0u), U(1u));
            PutF(0u, r.origin.x);
            PutF(1u, r.origin.y);
            PutF(2u, r.origin.z);
            PutF(3u, r.dir.x);
            PutF(4u, r.dir.y);
            PutF(5u, r.dir.z);
            PutF(6u, r.tMin);
            PutF(7u, r.tMax);
            break;
        }
        case kTwinMarchPaddedSampler: {
            const vec3 p = vec3(F(0u), F(1u), F(2u));
            const MarchTaps t = MarchTapsAt(march, p);
            const vec2 qt = MarchBlend(march, t);
            PutU(0u, t.base);
            PutF(1u, t.w.x);
            PutF(2u, t.w.y);
            PutF(3u, t.w.z);
            PutF(4u, qt.x);
            PutF(5u, qt.y);
            PutF(6u, MarchSampleQ(march, p));
            PutF(7u, SunLightMarch(march, p));
            PutF(8u, PointLightMarch(march, p));
            PutF(9u, PaddedBlendSky(march.strideY, march.strideZ, t));
            break;
        }
        // With the bound LayersGpu (tests/GlslTwinLayersTest.cpp).
        case kTwinMakeLayersRay: {
            const LayersRay r = MakeLayersRay(layers, U(0u), U(1u));
            PutF(0u, r.dir.x);
            PutF(1u, r.dir.y);
            PutF(2u, r.dir.z);
            PutF(3u, r.tNear);
            PutF(4u, r.tFar);
            const LayersWalk w = LayersWalkOf(layers, r.dir.z);
            PutI(5u, w.first);
            PutI(6u, w.step);
            PutU(7u, w.count);
            break;
        }
        case kTwinLayersTaps: {
            const MarchTaps t = PaddedTapsAt(layers.size, layers.strideY, layers.strideZ, vec3(F(0u), F(1u), F(2u)));
            const vec2 qt = PaddedBlend(layers.strideY, layers.strideZ, t);
            PutU(0u, t.base);
            PutF(1u, t.w.x);
            PutF(2u, t.w.y);
            PutF(3u, t.w.z);
            PutF(4u, qt.x);
            PutF(5u, qt.y);
            PutF(6u, TileWrap(F(3u), F(4u), F(5u)));
            PutF(7u, LayerHeight(layers, U(6u)));
            break;
        }
        case kTwinLayerFragment: {
            const LayersRay r = MakeLayersRay(layers, U(0u), U(1u));
            const SunPhases sunPhases = LayersSunPhases(layers, r);
            const LayerFragmentResult f = LayerFragment(layers, r, sunPhases, U(2u));
            PutU(0u, f.crossed ? 1u : 0u);
            PutU(1u, f.drawn ? 1u : 0u);
            PutF(2u, f.alpha);
            PutF(3u, f.color.x);
            PutF(4u, f.color.y);
            PutF(5u, f.color.z);
            PutF(6u, sunPhases.value[0]);
            const vec3 over = LayersOver(vec3(F(3u), F(4u), F(5u)), f.alpha, f.color);
            PutF(7u, over.x);
            PutF(8u, over.y);
            PutF(9u, over.z);
            break;
        }
        case kTwinLayersPixel: {
            const LayersPixelResult p = LayersPixel(layers, U(0u), U(1u));
            PutF(0u, p.color.x);
            PutF(1u, p.color.y);
            PutF(2u, p.color.z);
            PutU(3u, p.fragments);
            PutU(4u, p.drawn);
            break;
        }
        case kTwinLayersFade:
            PutF(0u, LayersFade(F(0u), F(1u), F(2u)));
            break;
        case kTwinBillboardFragment: {
            const LayersRay r = MakeLayersRay(layers, U(0u), U(1u));
            const SunPhases sunPhases = LayersSunPhases(layers, r);
            const LayerFragmentResult f = BillboardFragment(layers, r, sunPhases, LayersBillboardAt(U(2u)));
            PutU(0u, f.crossed ? 1u : 0u);
            PutU(1u, f.drawn ? 1u : 0u);
            PutF(2u, f.alpha);
            PutF(3u, f.color.x);
            PutF(4u, f.color.y);
            PutF(5u, f.color.z);
            PutF(6u, r.cosForward);
            break;
        }
        // With the bound MarchGpu's light (tests/GlslTwinTest.cpp InScatteredMatchesTheCpp).
        case kTwinSunGain: PutF(0u, SunGain(march.light, MakeSunPhases(march.light, F(0u)), F(1u))); break;
        case kTwinInScattered: {
            const LightSample s =
                LightSample(F(0u), F(1u), F(2u), vec3(F(3u), F(4u), F(5u)), vec3(F(6u), F(7u), F(8u)), F(9u));
            const vec3 c = InScattered(march.light, s);
            PutF(0u, c.x);
            PutF(1u, c.y);
            PutF(2u, c.z);
            PutF(3u, SkyPhase(march.light, s.dir));
            break;
        }
        case kTwinMakeSplat: {
            Splat s;
            const bool made = MakeSplat(frame, uvec3(U(0u), U(1u), U(2u)), F(3u), F(4u), F(5u), s);
            PutU(0u, made ? 1u : 0u);
            PutF(1u, s.px);
            PutF(2u, s.py);
            PutF(3u, s.size);
            PutF(4u, s.alphaScale);
            PutF(5u, s.r);
            PutF(6u, s.g);
            PutF(7u, s.b);
            PutI(8u, s.x0);
            PutI(9u, s.x1);
            PutI(10u, s.y0);
            PutI(11u, s.y1);
            break;
        }
    }
}
