#include "random.glsl"
#include "rules.glsl"
#include "shading.glsl"
#include "automaton.glsl"
#include "phase_table.glsl"
#include "light.glsl"
#include "march.glsl"
#include "layers.glsl"
// Stage `render_layers` (SPEC 15): one layer's fragment at pixel (x, y),
// LayerFragment of core/math/layers.glsl on the pixel's own ray (the fragment
// at gl_FragCoord (x + 0.5, y + 0.5) is the image's pixel (x, y), row 0 at the
// top, as in render_march.frag). A fragment not drawn is discarded; a drawn one
// blends (c, alpha) with SRC_ALPHA, ONE_MINUS_SRC_ALPHA over the layers behind.
// Built with LAYERS_BILLBOARDS it draws LOD0's billboard layerIndex instead (BillboardFragment).
layout(std140, binding = 0) uniform LayersBlock { LayersGpu layers; };
layout(std430, binding = 2) readonly buffer LayersVolume { vec2 layersQT[]; };
layout(std430, binding = 3) readonly buffer LayersPhaseTable { float layersPhaseTable[]; };
// fragments, drawn: 64-bit sums as (low, high) word pairs.
layout(std430, binding = 4) buffer LayersCounters { uint layersCounters[]; };
layout(std430, binding = 5) readonly buffer LayersMap { float layersMap[]; };  // read with wang opacity only
// The sky light's padded T_sky volume, read with the sky light on only.
layout(std430, binding = 7) readonly buffer LayersSkyVolume { float layersSkyT[]; };
#ifdef LAYERS_BILLBOARDS
layout(std430, binding = 6) readonly buffer LayersBillboards { LayersBillboard layersBillboards[]; };
LayersBillboard LayersBillboardAt(uint i) { return layersBillboards[i]; }
#else
LayersBillboard LayersBillboardAt(uint i) { return LayersBillboard(vec3(0.0), 0.0); }
#endif
flat in uint layerIndex;  // with LAYERS_BILLBOARDS, the billboard's index
layout(location = 0) out vec4 colour;

vec2 MarchFetchQT(uint paddedIndex) { return layersQT[paddedIndex]; }
float MarchFetchSkyT(uint paddedIndex) { return layersSkyT[paddedIndex]; }
float PhaseTableValue(uint i) { return layersPhaseTable[i]; }
float LayersMapValue(uint i) { return layersMap[i]; }
bool MarchBrickEmpty(uint brick) { return false; }  // march.glsl's bricks: never read here

void LayersCount(uint n) {
    const uint before = atomicAdd(layersCounters[2u * n], 1u);
    if (before + 1u < before) atomicAdd(layersCounters[2u * n + 1u], 1u);
}

void main() {
    const uint x = uint(gl_FragCoord.x), y = uint(gl_FragCoord.y);
    const LayersRay ray = MakeLayersRay(layers, x, y);
    const SunPhases sunPhases = LayersSunPhases(layers, ray);
#ifdef LAYERS_BILLBOARDS
    const LayerFragmentResult f = BillboardFragment(layers, ray, sunPhases, LayersBillboardAt(layerIndex));
#else
    const LayerFragmentResult f = LayerFragment(layers, ray, sunPhases, layerIndex);
#endif
    if (f.crossed) LayersCount(0u);
    if (!f.drawn) discard;
    LayersCount(1u);
    colour = vec4(f.color, f.alpha);
}
