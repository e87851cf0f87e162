// What both exact tracers (reference/Reference.h, reference/Trilinear.h) set up
// the same way: an Embree device and a scene of ONE user geometry, a box per
// run of voxels (or dual cells) whose intersect callback accumulates along the
// ray and never reports a hit, built robust at medium quality inside a TBB
// arena of the caller's thread count. Internal to reference/.
#pragma once

#include <embree3/rtcore.h>
#include <tbb/task_arena.h>

#include <mutex>
#include <string>

#include "core/base/Error.h"

namespace cb::ref {

class EmbreeRunScene {
  public:
    // `threads`: 0 = every hardware thread; the build and the caller's batches run in Arena().
    explicit EmbreeRunScene(int threads);
    ~EmbreeRunScene();
    EmbreeRunScene(const EmbreeRunScene&) = delete;
    EmbreeRunScene& operator=(const EmbreeRunScene&) = delete;

    struct Callbacks {
        RTCBoundsFunction bounds;
        RTCIntersectFunctionN intersect;
        RTCOccludedFunctionN occluded;  // never called (the tracers only intersect), but user geometry needs one
    };
    // Creates the device and commits a scene of `runs` user primitives (none:
    // an empty scene every ray misses). `user` is the geometry's user data.
    // The first Embree error, if any, comes back as "reference: Embree error N: ...".
    Status Build(unsigned runs, void* user, const Callbacks& callbacks);

    RTCScene Scene() const { return mScene; }
    tbb::task_arena& Arena() { return mArena; }

  private:
    static void OnDeviceError(void* user, RTCError code, const char* text);

    std::mutex mErrorMutex;
    std::string mError;
    RTCDevice mDevice = nullptr;
    RTCScene mScene = nullptr;
    tbb::task_arena mArena;
    int mThreads = 0;
};

}  // namespace cb::ref
