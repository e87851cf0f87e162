// A plain one-byte-per-voxel automaton written from SPEC section 3 alone, as
// the slow path the bit-field backends are checked against. It shares nothing
// with the backends but the hash of core/math/Random.h (tested on its own).
#pragma once

#include <cstdint>
#include <vector>

#include "core/math/Grid.h"
#include "core/math/Random.h"

namespace cb::test {

struct ByteState {
    std::vector<uint8_t> hum, act, cld;
};

struct ByteStepParams {
    uint32_t seed = 0, step = 0, qExt = 0, qHum = 0, qAct = 0;
    std::vector<int32_t> shiftX, shiftY;  // empty: no wind
};

inline ByteState ReferenceInitialState(const Extent3& e, uint32_t seed, uint32_t qHum0, uint32_t qAct0) {
    ByteState s;
    const size_t n = e.Count();
    s.hum.resize(n);
    s.act.resize(n);
    s.cld.assign(n, 0);
    for (uint32_t v = 0; v < n; ++v) {
        s.hum[v] = Rand24(seed, 0xFFFFFFFFu, 1, v) < qHum0;
        s.act[v] = Rand24(seed, 0xFFFFFFFFu, 2, v) < qAct0;
    }
    return s;
}

inline ByteState ReferenceStep(const Extent3& e, const ByteState& in, const std::vector<uint8_t>& region,
                               const ByteStepParams& p) {
    auto at = [&](const std::vector<uint8_t>& field, int64_t i, int64_t j, int64_t k) -> uint8_t {
        if (i < 0 || j < 0 || k < 0 || i >= e.nx || j >= e.ny || k >= e.nz) return 0;
        return field[size_t(i + int64_t(e.nx) * (j + int64_t(e.ny) * k))];
    };
    ByteState mid{in.hum, in.act, in.cld};
    for (int64_t k = 0; k < e.nz; ++k)
        for (int64_t j = 0; j < e.ny; ++j)
            for (int64_t i = 0; i < e.nx; ++i) {
                const uint32_t v = uint32_t(i + int64_t(e.nx) * (j + int64_t(e.ny) * k));
                // Dobashi eq. 2.4: i+-1, j+-1, k+-1, i+-2, j+-2, k-2.
                const bool f = at(in.act, i + 1, j, k) || at(in.act, i - 1, j, k) || at(in.act, i, j + 1, k) ||
                               at(in.act, i, j - 1, k) || at(in.act, i, j, k + 1) || at(in.act, i, j, k - 1) ||
                               at(in.act, i + 2, j, k) || at(in.act, i - 2, j, k) || at(in.act, i, j + 2, k) ||
                               at(in.act, i, j - 2, k) || at(in.act, i, j, k - 2);
                const bool hum = in.hum[v], act = in.act[v], cld = in.cld[v];
                bool hum1 = hum && !act, cld1 = cld || act, act1 = !act && hum && f;
                const uint32_t r = region[v];
                const uint32_t pExt = ((255 - r) * p.qExt + 127) / 255;
                const uint32_t pHum = (r * p.qHum + 127) / 255;
                const uint32_t pAct = (r * p.qAct + 127) / 255;
                bool cld2 = cld1 && !(Rand24(p.seed, p.step, 0, v) < pExt);
                bool hum2 = hum1 || (Rand24(p.seed, p.step, 1, v) < pHum);
                bool act2 = act1 || (Rand24(p.seed, p.step, 2, v) < pAct);
                cld2 = cld2 && r > 0;
                mid.hum[v] = hum2;
                mid.act[v] = act2;
                mid.cld[v] = cld2;
            }
    if (p.shiftX.empty()) return mid;
    ByteState out{mid.hum, mid.act, mid.cld};
    for (int64_t k = 0; k < e.nz; ++k)
        for (int64_t j = 0; j < e.ny; ++j)
            for (int64_t i = 0; i < e.nx; ++i) {
                const size_t v = size_t(i + int64_t(e.nx) * (j + int64_t(e.ny) * k));
                const int64_t si = i - p.shiftX[k], sj = j - p.shiftY[k];
                out.hum[v] = at(mid.hum, si, sj, k);
                out.act[v] = at(mid.act, si, sj, k);
                out.cld[v] = at(mid.cld, si, sj, k);
            }
    return out;
}

}  // namespace cb::test
