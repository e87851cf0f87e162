// Stage render_march on OpenGL against the CPU at the noise-layer scene's size: a benchmark run by hand
// (--gtest_also_run_disabled_tests --gtest_filter='*RenderMarchGLBench*'), not in CTest's runs.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <functional>
#include <string>
#include <vector>

#include "core/plan/SceneLoad.h"
#include "core/stages/noise/Noise.h"
#include "core/stages/render_march/RenderMarch.h"
#include "core/stages/shade/Shade.h"
#include "impl_cpu/BackendCpu.h"
#include "registry/Registry.h"
#include "tests/TestUtil.h"

namespace cb {
namespace {

// reports/march/gpu-march-gl.md: scenes/noise-layer.json's q and T made once
// by the CPU backend and uploaded to both, then render_march on the CPU and on
// GL alternately (CB_MARCH_ROUNDS rounds, default 5, after one warm-up call
// each) at 1280x720 and 640x360, per setting: wall ms (median, min, max), the
// process's CPU ms (both cores; llvmpipe's threads are in this process, so
// this is the backends' core time, less sensitive to a loaded machine than the
// wall time), GL device ms, the worst |d| between the two images and whether
// every counter agrees.
TEST(RenderMarchGLBench, DISABLED_NoiseLayerAgainstTheCpu) {
    auto glBackend = CreateBackend("gl");
    if (!glBackend) GTEST_SKIP() << glBackend.error().message;
    Backend& gl = **glBackend;
    cpu::BackendCpu cpu(0);
    auto loaded = LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/noise-layer.json");
    ASSERT_TRUE(loaded.has_value()) << loaded.error().message;
    const Scene scene = *loaded;
    const Extent3 e = scene.grid.size;
    auto q = test::MakeBuffer(cpu, BufferFormat::F32, e);
    auto t = test::MakeBuffer(cpu, BufferFormat::F32, e);
    ASSERT_TRUE(cpu.Noise(MakeNoiseParams(scene, 0), *q).has_value());
    ASSERT_TRUE(cpu.Shade(MakeShadeParams(scene), *q, *t).has_value());
    const std::vector<float> qHost = test::Read<float>(cpu, *q), tHost = test::Read<float>(cpu, *t);
    auto glQ = test::MakeFilled(gl, BufferFormat::F32, e, qHost);
    auto glT = test::MakeFilled(gl, BufferFormat::F32, e, tHost);
    const int rounds = std::getenv("CB_MARCH_ROUNDS") ? std::atoi(std::getenv("CB_MARCH_ROUNDS")) : 5;
    struct Setting {
        const char* name;
        std::function<void(MarchParams&)> edit;
    };
    const Setting settings[] = {
        {"shade, skip, HG (scene)", [](MarchParams&) {}},
        {"skipping off", [](MarchParams& p) { p.skipping = false; }},
        {"light march n_l 8", [](MarchParams& p) { p.light = MarchLightSource::March, p.lightSteps = 8; }},
        {"phase mie", [](MarchParams& p) { p.setup.light.phase.kind = PhaseKind::Mie; }},
    };
    const auto cpuNow = [] {
        timespec ts{};
        clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
        return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
    };
    const auto median = [](std::vector<double> v) {
        std::sort(v.begin(), v.end());
        return v[v.size() / 2];
    };
    // CB_MARCH_QUICK=1: the scene's setting only, at 1280x720 and 1x1 (the per-call passes without the rays).
    const bool quick = std::getenv("CB_MARCH_QUICK") != nullptr;
    const std::vector<std::pair<uint32_t, uint32_t>> sizes =
        quick ? std::vector<std::pair<uint32_t, uint32_t>>{{1280, 720}, {1, 1}}
              : std::vector<std::pair<uint32_t, uint32_t>>{{1280, 720}, {640, 360}};
    for (auto [w, h] : sizes)
        for (const Setting& setting : settings) {
            if (quick && &setting != &settings[0]) continue;
            CameraSettings camera = scene.render.cameras.at(0);
            Scene sized = scene;
            sized.render.width = w, sized.render.height = h;
            MarchParams p = MakeMarchParams(sized, camera, 0);
            setting.edit(p);
            auto cpuImage = test::MakeBuffer(cpu, BufferFormat::F32, {3, w, h});
            auto glImage = test::MakeBuffer(gl, BufferFormat::F32, {3, w, h});
            MarchStats cs, gs;
            std::vector<double> cpuMs, glMs, glDevice, cpuCore, glCore;
            for (int r = -1; r < rounds; ++r) {
                const double c0 = cpuNow();
                auto t0 = std::chrono::steady_clock::now();
                ASSERT_TRUE(cpu.RenderMarch(p, {q.get(), q.get(), t.get()}, *cpuImage, &cs).has_value());
                auto t1 = std::chrono::steady_clock::now();
                const double c1 = cpuNow();
                Status status = gl.RenderMarch(p, {glQ.get(), glQ.get(), glT.get()}, *glImage, &gs);
                ASSERT_TRUE(status.has_value()) << status.error().message;
                auto t2 = std::chrono::steady_clock::now();
                const double c2 = cpuNow();
                if (r < 0) continue;
                cpuCore.push_back(c1 - c0);
                glCore.push_back(c2 - c1);
                cpuMs.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
                glMs.push_back(std::chrono::duration<double, std::milli>(t2 - t1).count());
                glDevice.push_back(gl.LastDeviceMs().value_or(-1));
            }
            const std::vector<float> a = test::Read<float>(cpu, *cpuImage), b = test::Read<float>(gl, *glImage);
            double worst = 0;
            for (size_t i = 0; i < a.size(); ++i) worst = std::max(worst, double(std::fabs(a[i] - b[i])));
            const bool same = cs.rays == gs.rays && cs.samples == gs.samples && cs.lightSamples == gs.lightSamples &&
                              cs.bricksSkipped == gs.bricksSkipped && cs.bricks == gs.bricks &&
                              cs.emptyBricks == gs.emptyBricks;
            std::printf(
                "%4ux%-4u %-24s cpu %8.1f ms [%7.1f, %7.1f] core %8.1f  gl %8.1f ms [%7.1f, %7.1f] core "
                "%8.1f device %8.1f  rays %llu samples %llu light %llu skipped %llu  worst %.3g  counters %s\n",
                w, h, setting.name, median(cpuMs), *std::min_element(cpuMs.begin(), cpuMs.end()),
                *std::max_element(cpuMs.begin(), cpuMs.end()), median(cpuCore), median(glMs),
                *std::min_element(glMs.begin(), glMs.end()), *std::max_element(glMs.begin(), glMs.end()),
                median(glCore), median(glDevice), (unsigned long long)gs.rays, (unsigned long long)gs.samples,
                (unsigned long long)gs.lightSamples, (unsigned long long)gs.bricksSkipped, worst,
                same ? "equal" : "DIFFER");
            EXPECT_LE(worst, 1e-4);
            EXPECT_TRUE(same);
        }
}

}  // namespace
}  // namespace cb
