#version 450
// Stage `shade` (SPEC 6): several slices of the inverse shear-warp in one
// dispatch, the same T as shade_slice.comp bit for bit. Each workgroup owns a
// kTile x kTile tile of the (u, v) plane. Cell (a, b) of a slice reads the
// previous slice's cells a + u0 .. a + u0 + 1, b + v0 .. b + v0 + 1, so the
// group needs, of the slice `steps` slices before its last, a region wider than
// its tile by the cone of its tiles: per slice back, min(u0, 0) cells before
// the tile and max(u0 + 1, 0) after it (one cell in all for u0 = -1 or 0, two
// for u0 = 1, a 45-degree tie; the host halves the steps then). The group loads
// that region of the slice before the dispatch (or starts from slice 0, T = 1),
// computes slice by slice a region narrower each time in shared memory, and
// writes its own tile of every slice to T. Cells outside the plane hold T = 1
// and read q = 0, as shade_slice's TapT/TapQ. No group reads another group's
// cells of this dispatch's slices: the only cross-group dependency is on the
// slice before, which an earlier dispatch wrote (a barrier between
// dispatches); no spin-waits.
#extension GL_GOOGLE_include_directive : require
#include "shading.glsl"

const int kTile = 32;             // the tile each group writes, per axis
const int kHalo = 16;             // the region's width beyond the tile at most: steps * (hi - lo) <= kHalo
const int kRegion = kTile + kHalo;  // the widest region held (the slice before the first computed)

layout(local_size_x = kRegion) in;  // one invocation per column of the region
layout(std430, binding = 0) readonly buffer Q { float q[]; };
layout(std430, binding = 1) buffer T { float t[]; };
layout(push_constant) uniform Params {
    uint nu, nv;              // slice size
    uint strideU, strideV, strideW;
    uint nw, sunAbove;        // slice m has w index sunAbove ? nw - 1 - m : m
    uint begin, end;          // the slices [begin, end) of the sweep this dispatch computes (the host keeps the region within kRegion)
    int u0, v0;               // tap offset of the previous slice
    float fu, fv;
    uint beer;                // 1: beer, 0: thesis
    float depthPerQ, thesisAr, scatterGain;
    uint storage;
} pc;

// Two slices of the region, row stride kRegion: 2 * 48 * 48 * 4 = 18 KiB.
shared float held[2 * kRegion * kRegion];

uint SliceBase(uint m) { return (pc.sunAbove != 0u ? pc.nw - 1u - m : m) * pc.strideW; }
bool Inside(int a, int b) { return a >= 0 && b >= 0 && a < int(pc.nu) && b < int(pc.nv); }
float TapQ(uint base, int a, int b) {
    if (!Inside(a, b)) return 0.0;
    return q[base + uint(a) * pc.strideU + uint(b) * pc.strideV];
}

void main() {
    const int a0 = int(gl_WorkGroupID.x) * kTile, b0 = int(gl_WorkGroupID.y) * kTile;
    const int x = int(gl_LocalInvocationIndex);  // this invocation's column of the region
    // Per step back from the last slice, the region grows by -lo cells before the tile and hi after it.
    const int loU = min(pc.u0, 0), hiU = max(pc.u0 + 1, 0), loV = min(pc.v0, 0), hiV = max(pc.v0 + 1, 0);
    // From slice 0 itself (T = 1, written here) or from the slice before `begin` (read).
    const bool fromFirst = pc.begin == 0u;
    const int steps = int(pc.end - pc.begin) - (fromFirst ? 1 : 0);
    if (fromFirst) {
        const uint base = SliceBase(0u);
        const int a = a0 + x;
        for (int b = b0; x < kTile && b < b0 + kTile; ++b)
            if (Inside(a, b)) t[base + uint(a) * pc.strideU + uint(b) * pc.strideV] = 1.0;
    }
    // Shared memory holds every step's region in one frame: local (x, y) is cell
    // (ou + x, ov + y), the first region's corner. The regions nest (each step's
    // within the step before), so a step's taps are at the same local positions
    // one step earlier. Cells outside the plane are set to 1 here in both
    // buffers and never written again; only cells inside the plane are computed.
    const int ou = a0 + steps * loU, ov = b0 + steps * loV;
    {
        // Step 0: slice 0 (all 1) or the slice before `begin`, kTile + steps * (hi - lo) cells a side.
        const uint base = fromFirst ? 0u : SliceBase(pc.begin - 1u);
        const int a = ou + x;
        for (int y = 0; x < kTile + steps * (hiU - loU) && y < kTile + steps * (hiV - loV); ++y) {
            const int b = ov + y;
            if (!Inside(a, b)) {
                held[y * kRegion + x] = 1.0;
                held[kRegion * kRegion + y * kRegion + x] = 1.0;
            } else {
                held[y * kRegion + x] = fromFirst ? 1.0 : t[base + uint(a) * pc.strideU + uint(b) * pc.strideV];
            }
        }
    }
    for (int j = 1; j <= steps; ++j) {
        memoryBarrierShared();
        barrier();
        // Step j computes slice m from slice m - 1, held at step j - 1 in the
        // other buffer: cell (a, b) taps (a + u0 .. a + u0 + 1, b + v0 .. b + v0 + 1).
        const uint m = pc.begin + uint(j) - (fromFirst ? 0u : 1u);
        const uint base = SliceBase(m), previousBase = SliceBase(m - 1u);
        const int first = (steps - j) * loU - steps * loU, firstV = (steps - j) * loV - steps * loV;
        // The part of this step's region inside the plane, local: [xBegin, xEnd) x [yBegin, yEnd).
        const int xBegin = max(first, -ou), xEnd = min(first + kTile + (steps - j) * (hiU - loU), int(pc.nu) - ou);
        const int yBegin = max(firstV, -ov), yEnd = min(firstV + kTile + (steps - j) * (hiV - loV), int(pc.nv) - ov);
        const int current = (j & 1) * kRegion * kRegion, previous = ((j - 1) & 1) * kRegion * kRegion;
        const int a = ou + x;
        if (x >= xBegin && x < xEnd)
            for (int y = yBegin; y < yEnd; ++y) {
                const int b = ov + y;
                const int p = previous + (y + pc.v0) * kRegion + x + pc.u0;
                const float tt = Bilinear(held[p], held[p + 1], held[p + kRegion], held[p + kRegion + 1], pc.fu, pc.fv);
                const int ua = a + pc.u0, vb = b + pc.v0;
                const float qs = Bilinear(TapQ(previousBase, ua, vb), TapQ(previousBase, ua + 1, vb),
                                          TapQ(previousBase, ua, vb + 1), TapQ(previousBase, ua + 1, vb + 1), pc.fu,
                                          pc.fv);
                const float value = StoreTransmittance(
                    pc.storage, tt, SliceFactor(pc.beer, pc.depthPerQ, pc.thesisAr, pc.scatterGain, qs));
                if (a >= a0 && a < a0 + kTile && b >= b0 && b < b0 + kTile)
                    t[base + uint(a) * pc.strideU + uint(b) * pc.strideV] = value;
                held[current + y * kRegion + x] = value;
            }
    }
}
