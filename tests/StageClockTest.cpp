// The clocks a stage's call is timed on (core/pipeline/StageAdapter.h Timed,
// core/base/ProcessCpuTime.h), and the work the test-only slowdown adds
// (BackendCpu::BusyFor), against calls whose CPU use is known: threads that
// spin for a given CPU time, and a call that sleeps.
#include <gtest/gtest.h>

#include <chrono>
#include <optional>
#include <thread>

#include "core/base/ProcessCpuTime.h"
#include "core/pipeline/StageAdapter.h"
#include "impl_cpu/BackendCpu.h"

namespace cb {
namespace {

constexpr StageCountLabel kClockTestLabel{"region", "cpu", 0, ""};

TEST(StageClock, CpuTimeCountsEveryThreadOfTheCall) {
    cpu::BackendCpu backend(2);
    StageCallRecord record;
    // Two threads, 30 ms of CPU time each: 60 ms of the process's CPU time, in at least 30 ms.
    ASSERT_TRUE(Timed(backend, record, kClockTestLabel, false, std::nullopt, [] {
        std::thread other([] { SpinCpuFor(30); });
        SpinCpuFor(30);
        other.join();
        return Status{};
    }));
    EXPECT_GE(record.cpuMs, 60.0);
    EXPECT_LT(record.cpuMs, 60.0 + 15.0);  // starting a thread and reading the clocks
    EXPECT_GE(record.ms, 30.0);
}

TEST(StageClock, CpuTimeLeavesOutWaiting) {
    cpu::BackendCpu backend(2);
    StageCallRecord record;
    ASSERT_TRUE(Timed(backend, record, kClockTestLabel, false, std::nullopt, [] {
        std::this_thread::sleep_for(std::chrono::milliseconds(30));
        return Status{};
    }));
    EXPECT_GE(record.ms, 30.0);
    EXPECT_LT(record.cpuMs, 5.0);
}

TEST(StageClock, CallsAddUp) {
    cpu::BackendCpu backend(2);
    StageCallRecord record;
    for (int n = 0; n < 2; ++n)
        ASSERT_TRUE(Timed(backend, record, kClockTestLabel, false, std::nullopt, [] {
            SpinCpuFor(10);
            return Status{};
        }));
    EXPECT_GE(record.cpuMs, 20.0);
    EXPECT_LT(record.cpuMs, 20.0 + 10.0);
}

// BusyFor(wall, cpu): the arena's threads use `cpu` of CPU time together, none more than `wall`.
TEST(StageClock, BusyForUsesTheCpuTimeAsked) {
    cpu::BackendCpu backend(2);
    ASSERT_EQ(backend.Threads(), 2);
    double before = ProcessCpuMs();
    backend.BusyFor(40, 60);  // 30 ms on each thread
    double used = ProcessCpuMs() - before;
    EXPECT_GE(used, 60.0);
    EXPECT_LT(used, 60.0 + 15.0);  // waking the worker and reading the clocks
    before = ProcessCpuMs();
    backend.BusyFor(20, 100);  // more than two threads can use in 20 ms each: 40
    used = ProcessCpuMs() - before;
    EXPECT_GE(used, 40.0);
    EXPECT_LT(used, 40.0 + 15.0);
}

}  // namespace
}  // namespace cb
