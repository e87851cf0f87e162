// Stage `smooth`'s types (SPEC 4, docs/contract.md): its settings (section `smooth`).
// The scene (core/scene/Scene.h) and the backend interface (core/pipeline/Backend.h) include
// this header; the stage's reader, parameters, descriptor and call are beside it.
#pragma once

namespace cb {

inline constexpr int kMaxSmoothRadius = 2;

struct SmoothSettings {
    int radius = 1;  // 0 .. kMaxSmoothRadius
};

}  // namespace cb
