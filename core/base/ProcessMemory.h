// How much memory this process may use: the smallest of the machine's memory,
// the cgroup's limit (v2 memory.max, v1 memory.limit_in_bytes) and RLIMIT_AS.
// Linux only; a figure the system does not give is left out.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace cb {

// A byte count and what set it, e.g. {1610612736, "RLIMIT_AS"}.
struct MemoryFigure {
    uint64_t bytes = 0;
    std::string source;
};

// The fixed ceiling, independent of what is in use now: min(physical memory ("physical memory"), the cgroup limit
// ("cgroup memory limit"), RLIMIT_AS ("RLIMIT_AS")). The scene loader's check. nullopt when none is known.
std::optional<MemoryFigure> ProcessMemoryLimit();

// What the process may still allocate now: min(MemAvailable ("available memory"), the cgroup limit minus its
// usage ("cgroup memory limit"), RLIMIT_AS minus this process's VmSize ("RLIMIT_AS")). A backend's check before it
// allocates. nullopt when none is known.
std::optional<MemoryFigure> ProcessAvailableMemory();

// Physical memory in bytes, or nullopt when the system does not say.
std::optional<uint64_t> PhysicalMemoryBytes();

// Bytes in GiB with one decimal, e.g. "348.0".
std::string FormatGiB(uint64_t bytes);

// Saturating arithmetic for byte counts.
inline uint64_t SaturatingAdd(uint64_t a, uint64_t b) {
    uint64_t r;
    return __builtin_add_overflow(a, b, &r) ? UINT64_MAX : r;
}
inline uint64_t SaturatingMul(uint64_t a, uint64_t b) {
    uint64_t r;
    return __builtin_mul_overflow(a, b, &r) ? UINT64_MAX : r;
}

}  // namespace cb
