#version 450
// Stage `render_layers` (SPEC 15), pass 2: one invocation per pixel in 8 x 8
// workgroups, LayersPixel of core/math/layers.glsl (the CPU's loop over the
// layers the pixel's ray crosses, back to front, then LOD0's billboards, those
// that meet the workgroup's tile, picked 64 at a time in shared memory), over
// the padded (q_alpha, T) volume of pass 1 (march_volume.comp, wrapped with tiling) and, with the sky light,
// T_sky's (sky_volume.comp). Writes linear RGB
// and adds the LayersStats counters (a reduction in shared memory, then one
// atomic per workgroup and counter).
#extension GL_GOOGLE_include_directive : require
#include "random.glsl"
#include "shading.glsl"
#include "phase_table.glsl"
#include "light.glsl"
#include "march.glsl"
#include "layers.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(std430, binding = 0) readonly buffer Frame { LayersGpu frame; };
layout(std430, binding = 1) readonly buffer Volume { vec2 volume[]; };  // (q_alpha, T)
layout(std430, binding = 2) readonly buffer Mie { float mieTable[]; };  // read only with phase Mie
layout(std430, binding = 3) writeonly buffer Image { float image[]; };
// Words 2 n, 2 n + 1: counter n (low, high) of fragments, drawn.
layout(std430, binding = 4) buffer Stats { uint stats[]; };
layout(std430, binding = 5) readonly buffer Map { float layersMap[]; };  // read with wang opacity only
layout(std430, binding = 6) readonly buffer Billboards { LayersBillboard billboards[]; };  // LOD0, back to front
// The sky light's T_sky, padded like the volume (sky_volume.comp); read only with the sky light on.
layout(std430, binding = 7) readonly buffer SkyVolume { float skyVolume[]; };

vec2 MarchFetchQT(uint paddedIndex) { return volume[paddedIndex]; }
float MarchFetchSkyT(uint paddedIndex) { return skyVolume[paddedIndex]; }
float PhaseTableValue(uint i) { return mieTable[i]; }
float LayersMapValue(uint i) { return layersMap[i]; }
LayersBillboard LayersBillboardAt(uint i) { return billboards[i]; }
bool MarchBrickEmpty(uint brick) { return false; }  // march.glsl's bricks: never read here

shared uint gCounts[2];
// LOD0: the billboards of one chunk of 64 that meet this workgroup's tile, in the list's order.
shared uint gKeep[64];
shared uint gKept[64];
shared uint gKeptCount;

void AddCounter(uint n, uint v) {
    if (v == 0u) return;
    const uint before = atomicAdd(stats[2u * n], v);
    if (before + v < before) atomicAdd(stats[2u * n + 1u], 1u);
}

// Whether billboard b's fragments can fall in the pixels [x0, x0 + 8) x [y0, y0 + 8): its quad projected (a
// rectangle, parallel to the image plane) grown as core/math/Layers.h LayersBillboardRect grows it, and by one more
// pixel for this float arithmetic; true where the arithmetic fails (conservative: a kept billboard without a
// fragment here changes nothing).
bool BillboardMeetsTile(LayersGpu s, LayersBillboard b, float x0, float y0) {
    const float depth = b.depth, focal = s.focalPx;
    const vec3 rel = b.centre - s.eye;
    const vec3 magnitude = max(abs(b.centre), abs(s.eye));
    const float margin = 2.0 * depth / focal + 1e-5 * max(1.0, max(magnitude.x, max(magnitude.y, magnitude.z)));
    const float x = dot(rel, s.right), y = dot(rel, s.up);
    const float hw = s.halfWidth + margin, hh = s.halfHeight + margin;
    const float W = float(s.width), H = float(s.height);
    const float left = 0.5 * W + focal * (x - hw) / depth - 1.0, right = 0.5 * W + focal * (x + hw) / depth + 1.0;
    const float top = 0.5 * H - focal * (y + hh) / depth - 1.0, bottom = 0.5 * H - focal * (y - hh) / depth + 1.0;
    return !(right < x0 || left > x0 + 8.0 || bottom < y0 || top > y0 + 8.0);
}

void main() {
    const uint local = gl_LocalInvocationIndex;
    if (local < 2u) gCounts[local] = 0u;
    barrier();
    const LayersGpu s = frame;
    const uint x = gl_GlobalInvocationID.x, y = gl_GlobalInvocationID.y;
    const bool inside = x < s.width && y < s.height;
    // The layers (LayersPixel without the billboards), then the billboards in the list's order: those of each
    // chunk of 64 that meet the tile, which the workgroup picks together. The same fragments in the same order as
    // LayersPixel with the whole list: a billboard left out has none in the tile.
    LayersGpu layersOnly = s;
    layersOnly.billboardCount = 0u;
    LayersPixelResult r = LayersPixelResult(s.background, 0u, 0u);
    if (inside) r = LayersPixel(layersOnly, x, y);
    const LayersRay ray = MakeLayersRay(s, min(x, s.width - 1u), min(y, s.height - 1u));
    const SunPhases sunPhases = LayersSunPhases(s, ray);
    const float tileX = float(gl_WorkGroupID.x * 8u), tileY = float(gl_WorkGroupID.y * 8u);
    for (uint base = 0u; base < s.billboardCount; base += 64u) {
        const uint n = base + local;
        gKeep[local] = n < s.billboardCount && BillboardMeetsTile(s, LayersBillboardAt(n), tileX, tileY) ? 1u : 0u;
        barrier();
        if (local == 0u) {
            uint kept = 0u;
            for (uint i = 0u; i < 64u; ++i)
                if (gKeep[i] != 0u) gKept[kept++] = base + i;
            gKeptCount = kept;
        }
        barrier();
        if (inside)
            for (uint i = 0u; i < gKeptCount; ++i) {
                const LayerFragmentResult f = BillboardFragment(s, ray, sunPhases, LayersBillboardAt(gKept[i]));
                r.fragments += f.crossed ? 1u : 0u;
                if (!f.drawn) continue;
                ++r.drawn;
                r.color = LayersOver(r.color, f.alpha, f.color);
            }
        barrier();
    }
    if (inside) {
        const uint pixel = x + s.width * y;
        image[3u * pixel] = r.color.x;
        image[3u * pixel + 1u] = r.color.y;
        image[3u * pixel + 2u] = r.color.z;
        atomicAdd(gCounts[0], r.fragments);
        atomicAdd(gCounts[1], r.drawn);
    }
    barrier();
    if (local < 2u) AddCounter(local, gCounts[local]);
}
