#include "reference/EmbreeRuns.h"

namespace cb::ref {

EmbreeRunScene::EmbreeRunScene(int threads)
    : mArena(threads > 0 ? threads : tbb::task_arena::automatic), mThreads(threads) {}

EmbreeRunScene::~EmbreeRunScene() {
    if (mScene) rtcReleaseScene(mScene);
    if (mDevice) rtcReleaseDevice(mDevice);
}

void EmbreeRunScene::OnDeviceError(void* user, RTCError code, const char* text) {
    auto& self = *static_cast<EmbreeRunScene*>(user);
    std::lock_guard lock(self.mErrorMutex);
    if (self.mError.empty()) self.mError = "Embree error " + std::to_string(int(code)) + ": " + (text ? text : "");
}

Status EmbreeRunScene::Build(unsigned runs, void* user, const Callbacks& callbacks) {
    mDevice = rtcNewDevice(mThreads > 0 ? ("threads=" + std::to_string(mThreads)).c_str() : nullptr);
    if (!mDevice)
        return MakeError("reference: cannot create the Embree device (error " +
                         std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
    rtcSetDeviceErrorFunction(mDevice, OnDeviceError, this);
    mScene = rtcNewScene(mDevice);
    rtcSetSceneFlags(mScene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(mScene, RTC_BUILD_QUALITY_MEDIUM);
    if (runs > 0) {
        RTCGeometry geometry = rtcNewGeometry(mDevice, RTC_GEOMETRY_TYPE_USER);
        rtcSetGeometryUserPrimitiveCount(geometry, runs);
        rtcSetGeometryUserData(geometry, user);
        rtcSetGeometryBoundsFunction(geometry, callbacks.bounds, nullptr);
        rtcSetGeometryIntersectFunction(geometry, callbacks.intersect);
        rtcSetGeometryOccludedFunction(geometry, callbacks.occluded);
        rtcSetGeometryBuildQuality(geometry, RTC_BUILD_QUALITY_MEDIUM);
        rtcCommitGeometry(geometry);
        rtcAttachGeometry(mScene, geometry);
        rtcReleaseGeometry(geometry);
    }
    mArena.execute([&] { rtcCommitScene(mScene); });
    std::lock_guard lock(mErrorMutex);
    if (!mError.empty()) return MakeError("reference: " + mError);
    return {};
}

}  // namespace cb::ref
