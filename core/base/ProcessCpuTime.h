// The CPU time this process has used, on every one of its threads: what a
// stage's calls cost the machine, whatever else runs beside them. Unlike wall
// time it does not grow while the process waits for a core another job holds,
// nor while it waits for a device, a lock or the disk.
#pragma once

#include <ctime>

namespace cb {

// Process CPU time in ms (CLOCK_PROCESS_CPUTIME_ID: the sum over the process's
// threads, the calling thread's current slice included).
inline double ProcessCpuMs() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
}

// The calling thread's CPU time in ms (CLOCK_THREAD_CPUTIME_ID).
inline double ThreadCpuMs() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
}

// Spins the calling thread until it has used `ms` more of CPU time (however
// long other jobs keep it off its core).
inline void SpinCpuFor(double ms) {
    const double until = ThreadCpuMs() + ms;
    while (ThreadCpuMs() < until) {
    }
}

}  // namespace cb
