// The functions tests/twin/twin.comp runs, one name and number each: the one
// list both languages read. The C++ (tests/GlslTwinHarness.h) makes of it the
// constants test::kTwin<Name>, the `fn` a case asks for; twin.comp makes the
// GLSL constants kTwin<Name> that label its switch. Include after defining
// CB_TWIN_FN(name, number); a case is never a bare number in either language.
// No include guard: each language includes it once with its own CB_TWIN_FN.
// ---- random.glsl, rules.glsl, shading.glsl ----
CB_TWIN_FN(LowBias32, 0u)
CB_TWIN_FN(StreamKey, 1u)
CB_TWIN_FN(Rand24FromKey, 2u)
CB_TWIN_FN(RegionEventFires, 3u)
CB_TWIN_FN(EllipsoidWeight, 4u)
CB_TWIN_FN(QuantizeRegion, 5u)
CB_TWIN_FN(SmoothWeight, 6u)
CB_TWIN_FN(ExpNonPositive, 7u)
CB_TWIN_FN(RoundToHalf, 8u)
CB_TWIN_FN(RoundToUnorm8, 9u)
CB_TWIN_FN(RoundToStorage, 10u)
CB_TWIN_FN(Lerp, 11u)
CB_TWIN_FN(Bilinear, 12u)
CB_TWIN_FN(PhaseValue, 13u)
CB_TWIN_FN(DualLobePhase, 69u)
CB_TWIN_FN(SplatKernel, 14u)
CB_TWIN_FN(SliceFactor, 15u)
CB_TWIN_FN(StoreTransmittance, 16u)
CB_TWIN_FN(GroundShadow, 17u)
CB_TWIN_FN(WangShadow, 45u)
CB_TWIN_FN(UpsampleTap, 18u)
// ---- automaton.glsl ----
CB_TWIN_FN(CaRowNeighbours, 19u)
CB_TWIN_FN(CaGrowth, 20u)
CB_TWIN_FN(CaVoxelEvents, 21u)
CB_TWIN_FN(CaInitialVoxel, 22u)
CB_TWIN_FN(MakeCaEvents, 23u)
// ---- splat.glsl ----
CB_TWIN_FN(SplatQ, 24u)
CB_TWIN_FN(SplatCoord, 25u)
CB_TWIN_FN(SplatAlpha, 26u)
CB_TWIN_FN(MakeSplat, 27u)
// ---- noise.glsl ----
CB_TWIN_FN(NoisePerlin, 28u)
CB_TWIN_FN(NoiseSimplex, 29u)
CB_TWIN_FN(NoiseWorley, 30u)
CB_TWIN_FN(NoiseFbm, 31u)
CB_TWIN_FN(NoiseForming, 32u)
CB_TWIN_FN(NoiseHeightAndTower, 33u)
// ---- phase_table.glsl, march.glsl ----
CB_TWIN_FN(ArcCos, 34u)
CB_TWIN_FN(SamplePhaseTable, 35u)
CB_TWIN_FN(LightPhase, 36u)  // light.glsl's, of a zeroed MarchGpu's light
CB_TWIN_FN(ClipRayToBox, 37u)
CB_TWIN_FN(MarchStepAt, 38u)
CB_TWIN_FN(MarchAdaptiveLanding, 68u)
CB_TWIN_FN(MarchJitter, 39u)
CB_TWIN_FN(RayExitFromBox, 40u)
CB_TWIN_FN(PowderTerm, 41u)
CB_TWIN_FN(MarchKernelFormulas, 42u)
CB_TWIN_FN(MarchBrickAt, 67u)
// With the bound MarchGpu.
CB_TWIN_FN(MakePixelRay, 43u)
CB_TWIN_FN(MarchPaddedSampler, 44u)
// ---- ground.glsl ----
CB_TWIN_FN(GroundHit, 46u)
CB_TWIN_FN(GroundShadowAt, 47u)
CB_TWIN_FN(GroundChannel, 48u)
// ---- layers.glsl, with the bound LayersGpu ----
CB_TWIN_FN(MakeLayersRay, 60u)
CB_TWIN_FN(LayersTaps, 61u)
CB_TWIN_FN(LayerFragment, 62u)
CB_TWIN_FN(LayersPixel, 63u)
CB_TWIN_FN(LayersFade, 64u)
CB_TWIN_FN(BillboardFragment, 66u)
// ---- light.glsl, with the bound MarchGpu's light ----
CB_TWIN_FN(InScattered, 65u)
CB_TWIN_FN(SunGain, 70u)
// ---- shafts.glsl ----
CB_TWIN_FN(ShaftsColumnAt, 71u)
CB_TWIN_FN(ShaftsLayerForm, 72u)
CB_TWIN_FN(ShaftsFalloff, 73u)
