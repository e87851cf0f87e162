// GLSL twin of core/math/Layers.h (SPEC 15): a pixel's ray, the padded (q, T)
// taps with the tiling's wrap, one layer's or billboard's fragment, the
// back-to-front walk and the per-pixel loop. The same operations in the same order, `precise` where
// the CPU (built with -ffp-contract=off) rounds each product.
//
// Include after random.glsl, shading.glsl, phase_table.glsl, light.glsl and march.glsl,
// whose pixel ray, padded sampler (PaddedTapsAt, PaddedBlend), SegmentTransmittance
// and phase it uses. The including shader defines march.glsl's MarchFetchQT as the
// layers' padded (q_alpha, T) volume and MarchFetchSkyT as T_sky's (read with the sky light on), (nx+2) x (ny+2) x (nz+2) with voxel
// (i, j, k) at (i+1, j+1, k+1), PhaseTableValue (phase Mie only) and
//   float LayersMapValue(uint i);  // the modulation map, nx * ny, x fastest (wang opacity only)
//   LayersBillboard LayersBillboardAt(uint i);  // the billboards in drawing order (billboardCount of them)
#ifndef CLOUDBENCH_LAYERS_GLSL
#define CLOUDBENCH_LAYERS_GLSL

// core/pipeline/LayersGpu.h, member for member.
struct LayersGpu {
    vec3 eye;  // voxel units
    float focalPx;
    vec3 forward;
    float nearPlane;  // metres
    vec3 right;
    float farPlane;  // metres
    vec3 up;
    float voxelSize;  // h, metres
    vec3 size;        // the grid
    float sigmaH;
    vec3 invSize;  // 1 / size
    float spacing;  // nz / N
    vec3 sun;       // toward the sun
    float outer2;   // extent^2
    vec3 background;
    float maxLength;  // l_max
    uint width;
    uint height;
    uint count;  // N
    uint flags;  // kLayers* bits
    uint strideY;  // px
    uint strideZ;  // px * py
    float lightScale;  // T's factor (relighting)
    float fadeInv2;
    vec2 drift;  // the wind's drift (voxel units)
    float coverage;  // C (wang)
    float density;   // D_w (wang)
    float inner2;    // r0^2: LOD0's radius squared (0: no billboards)
    float halfWidth;   // W_p / 2 (billboards)
    float halfHeight;  // H_p / 2
    float billboardLength;  // a billboard fragment's path times cos(ray, forward) (beer)
    uint billboardCount;
    LightGpu light;  // light.glsl
};

const uint kLayersTiling = 1u;
const uint kLayersWang = 2u;

float LayersMapValue(uint i);

// core/math/Layers.h LayersBillboard: its centre (voxel units) and view depth.
struct LayersBillboard {
    vec3 centre;
    float depth;
};
LayersBillboard LayersBillboardAt(uint i);

float LayerHeight(LayersGpu s, uint i) {
    precise float z = (float(i) + 0.5) * s.spacing;
    return z;
}

// core/math/Layers.h LayersFade, written out (no smoothstep).
float LayersFade(float r2, float outer2, float fadeInv2) {
    if (!(fadeInv2 > 0.0)) return 1.0;
    precise float d = (outer2 - r2) * fadeInv2;
    const float w = min(max(d, 0.0), 1.0);
    precise float f = (w * w) * (3.0 - 2.0 * w);
    return f;
}

struct LayersRay {
    vec3 dir;
    float tNear, tFar;
    float cosForward;
};

// core/math/Layers.h MakeLayersRay (PixelRayDirection, then the planes' distances).
LayersRay MakeLayersRay(LayersGpu s, uint x, uint y) {
    float inv;
    LayersRay r;
    r.dir = PixelRayDirection(s.forward, s.right, s.up, s.focalPx, uvec2(s.width, s.height), x, y, inv);
    precise float perDepth = 1.0 / (s.voxelSize * inv);
    r.tNear = s.nearPlane * perDepth;
    r.tFar = s.farPlane * perDepth;
    r.cosForward = inv;
    return r;
}

// core/math/Layers.h LayersSunPhases.
SunPhases LayersSunPhases(LayersGpu s, LayersRay ray) { return MakeSunPhases(s.light, MarchDot(s.sun, ray.dir)); }

// core/math/Layers.h LayersMapAt.
float LayersMapAt(LayersGpu s, float x, float y) {
    const int nx = int(s.size.x), ny = int(s.size.y);
    precise float u = x - 0.5, v = y - 0.5;
    const float fu = floor(u), fv = floor(v);
    precise float wu = u - fu, wv = v - fv;
    int i0 = int(fu), i1 = i0 + 1, j0 = int(fv), j1 = j0 + 1;
    if ((s.flags & kLayersTiling) != 0u) {
        i0 = i0 < 0 ? i0 + nx : i0;
        i1 = i1 >= nx ? i1 - nx : i1;
        j0 = j0 < 0 ? j0 + ny : j0;
        j1 = j1 >= ny ? j1 - ny : j1;
    } else {
        i0 = clamp(i0, 0, nx - 1);
        i1 = clamp(i1, 0, nx - 1);
        j0 = clamp(j0, 0, ny - 1);
        j1 = clamp(j1, 0, ny - 1);
    }
    return Lerp(Lerp(LayersMapValue(uint(i0 + nx * j0)), LayersMapValue(uint(i1 + nx * j0)), wu),
                Lerp(LayersMapValue(uint(i0 + nx * j1)), LayersMapValue(uint(i1 + nx * j1)), wu), wv);
}

struct LayerFragmentResult {
    bool crossed, drawn;
    float alpha;
    vec3 color;
};

// core/math/Layers.h LayersSampleAt.
LayerFragmentResult LayersSampleAt(LayersGpu s, LayersRay ray, SunPhases sunPhases, float hx, float hy, float z, float r2,
                                   float length) {
    LayerFragmentResult f = LayerFragmentResult(false, false, 0.0, vec3(0.0));
    precise float x = (s.eye.x + hx) - s.drift.x, y = (s.eye.y + hy) - s.drift.y;
    if ((s.flags & kLayersTiling) != 0u) {
        x = TileWrap(x, s.size.x, s.invSize.x);
        y = TileWrap(y, s.size.y, s.invSize.y);
    } else if (!(x >= 0.0 && x <= s.size.x && y >= 0.0 && y <= s.size.y)) {
        return f;
    }
    f.crossed = true;
    const MarchTaps taps = PaddedTapsAt(s.size, s.strideY, s.strideZ, vec3(x, y, z));
    const vec2 qt = PaddedBlend(s.strideY, s.strideZ, taps);
    if (!(qt.x > 0.0)) return f;
    f.drawn = true;
    if ((s.flags & kLayersWang) != 0u) {
        f.alpha = CoverageModulate(qt.x, LayersMapAt(s, x, y), s.coverage, s.density);
    } else {
        precise float alpha = 1.0 - SegmentTransmittance(s.sigmaH, qt.x, length);
        f.alpha = alpha;
    }
    precise float faded = f.alpha * LayersFade(r2, s.outer2, s.fadeInv2);
    f.alpha = faded;
    precise float lit = qt.y * s.lightScale;  // T, or relit
    precise float gain = SunGain(s.light, sunPhases, lit);
    // The sample (voxel units, before the drift and the wrap).
    precise vec3 at = vec3(s.eye.x + hx, s.eye.y + hy, z);
    precise float skyGain = 0.0;
    if (s.light.skyOn != 0u) skyGain = PaddedBlendSky(s.strideY, s.strideZ, taps) * SkyPhase(s.light, ray.dir);
    f.color = InScattered(s.light, LightSample(gain, lit, 1.0, at, ray.dir, skyGain));
    return f;
}

// core/math/Layers.h LayerFragment.
LayerFragmentResult LayerFragment(LayersGpu s, LayersRay ray, SunPhases sunPhases, uint i) {
    LayerFragmentResult f = LayerFragmentResult(false, false, 0.0, vec3(0.0));
    const float dz = ray.dir.z;
    if (!(abs(dz) >= 1e-20)) return f;
    const float z = LayerHeight(s, i);
    precise float invDz = 1.0 / dz;
    precise float t = (z - s.eye.z) * invDz;
    if (!(t >= ray.tNear && t <= ray.tFar && t > 0.0)) return f;
    precise float hx = ray.dir.x * t, hy = ray.dir.y * t;
    precise float r2 = hx * hx + hy * hy;
    if (!(r2 <= s.outer2 && r2 >= s.inner2)) return f;
    precise float length = min(s.spacing * abs(invDz), s.maxLength);
    return LayersSampleAt(s, ray, sunPhases, hx, hy, z, r2, length);
}

// core/math/Layers.h BillboardFragment (the billboards' plane: s.right, s.up).
LayerFragmentResult BillboardFragment(LayersGpu s, LayersRay ray, SunPhases sunPhases, LayersBillboard bb) {
    LayerFragmentResult f = LayerFragmentResult(false, false, 0.0, vec3(0.0));
    precise float t = bb.depth / ray.cosForward;
    if (!(t >= ray.tNear && t <= ray.tFar && t > 0.0)) return f;
    precise float hx = ray.dir.x * t, hy = ray.dir.y * t, hz = ray.dir.z * t;
    precise float r2 = hx * hx + hy * hy;
    if (!(r2 < s.inner2 && r2 <= s.outer2)) return f;
    precise float ox = (s.eye.x + hx) - bb.centre.x, oy = (s.eye.y + hy) - bb.centre.y;
    precise float z = s.eye.z + hz;
    precise float oz = z - bb.centre.z;
    precise float u = ox * s.right.x + oy * s.right.y + oz * s.right.z;
    precise float v = ox * s.up.x + oy * s.up.y + oz * s.up.z;
    if (!(abs(u) <= s.halfWidth && abs(v) <= s.halfHeight)) return f;
    if (!(z >= 0.0 && z <= s.size.z)) return f;
    precise float length = min(s.billboardLength / ray.cosForward, s.maxLength);
    return LayersSampleAt(s, ray, sunPhases, hx, hy, z, r2, length);
}

vec3 LayersOver(vec3 C, float alpha, vec3 c) {
    precise float keep = 1.0 - alpha;
    precise vec3 r = vec3(alpha * c.x + keep * C.x, alpha * c.y + keep * C.y, alpha * c.z + keep * C.z);
    return r;
}

struct LayersWalk {
    int first, step;
    uint count;
};

LayersWalk LayersWalkOf(LayersGpu s, float dz) {
    LayersWalk w = LayersWalk(0, 0, 0u);
    const uint n = s.count;
    if (dz > 0.0) {
        uint lowest = n;
        while (lowest > 0u && LayerHeight(s, lowest - 1u) > s.eye.z) --lowest;
        w = LayersWalk(int(n) - 1, -1, n - lowest);
    } else if (dz < 0.0) {
        uint above = 0u;
        while (above < n && LayerHeight(s, above) < s.eye.z) ++above;
        w = LayersWalk(0, 1, above);
    }
    return w;
}

struct LayersPixelResult {
    vec3 color;
    uint fragments, drawn;
};

// core/math/Layers.h LayersPixel: the background, then the layers the ray crosses, back to front, then the billboards.
LayersPixelResult LayersPixel(LayersGpu s, uint x, uint y) {
    LayersPixelResult r = LayersPixelResult(s.background, 0u, 0u);
    const LayersRay ray = MakeLayersRay(s, x, y);
    const SunPhases sunPhases = LayersSunPhases(s, ray);
    const LayersWalk w = LayersWalkOf(s, ray.dir.z);
    for (uint n = 0u; n < w.count; ++n) {
        const uint i = uint(w.first + w.step * int(n));
        const LayerFragmentResult f = LayerFragment(s, ray, sunPhases, i);
        r.fragments += f.crossed ? 1u : 0u;
        if (!f.drawn) continue;
        ++r.drawn;
        r.color = LayersOver(r.color, f.alpha, f.color);
    }
    for (uint n = 0u; n < s.billboardCount; ++n) {
        const LayerFragmentResult f = BillboardFragment(s, ray, sunPhases, LayersBillboardAt(n));
        r.fragments += f.crossed ? 1u : 0u;
        if (!f.drawn) continue;
        ++r.drawn;
        r.color = LayersOver(r.color, f.alpha, f.color);
    }
    return r;
}

#endif  // CLOUDBENCH_LAYERS_GLSL
