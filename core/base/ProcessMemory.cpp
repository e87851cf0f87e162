#include "core/base/ProcessMemory.h"

#include <sys/resource.h>
#include <unistd.h>

#include <cstdio>
#include <sstream>
#include <string_view>

#include "core/base/SystemFile.h"

namespace cb {
namespace {


// Limits at or above this mean "no limit" (cgroup v1 writes 2^63 rounded down to a page).
constexpr uint64_t kUnlimited = uint64_t(1) << 62;

std::optional<uint64_t> ReadNumber(const std::string& path) {
    std::istringstream in(ReadSystemFile(path));
    std::string text;
    if (!(in >> text) || text == "max") return std::nullopt;
    try {
        const unsigned long long value = std::stoull(text);
        if (value >= kUnlimited) return std::nullopt;
        return uint64_t(value);
    } catch (...) {
        return std::nullopt;
    }
}

// A "Key: N kB" line of /proc/self/status or /proc/meminfo, in bytes.
std::optional<uint64_t> ReadKilobytes(const char* path, std::string_view key) {
    std::istringstream in(ReadSystemFile(path));
    std::string line;
    while (std::getline(in, line)) {
        if (!line.starts_with(key) || line.size() <= key.size() || line[key.size()] != ':') continue;
        std::istringstream fields(line.substr(key.size() + 1));
        uint64_t kb = 0;
        if (fields >> kb) return SaturatingMul(kb, 1024);
    }
    return std::nullopt;
}

struct CgroupMemory {
    uint64_t limit = 0, usage = 0;
};

// The tightest memory limit of this process's cgroup and its ancestors (limits nest), with that cgroup's usage.
// Version 2 ("0::/path" in /proc/self/cgroup) and version 1 (the "memory" controller); in a container the own
// path is often not mounted, so every folder from it up to the mount is tried.
std::optional<CgroupMemory> CgroupLimit() {
    std::istringstream in(ReadSystemFile("/proc/self/cgroup"));
    std::string line;
    std::optional<CgroupMemory> best;
    while (std::getline(in, line)) {
        const size_t first = line.find(':'), second = line.find(':', first + 1);
        if (first == std::string::npos || second == std::string::npos) continue;
        const std::string controllers = line.substr(first + 1, second - first - 1);
        std::string path = line.substr(second + 1);
        std::string mount, limitFile, usageFile;
        if (line.starts_with("0::")) {
            mount = "/sys/fs/cgroup", limitFile = "/memory.max", usageFile = "/memory.current";
        } else if (("," + controllers + ",").find(",memory,") != std::string::npos) {
            mount = "/sys/fs/cgroup/memory", limitFile = "/memory.limit_in_bytes", usageFile = "/memory.usage_in_bytes";
        } else {
            continue;
        }
        for (;;) {
            if (path == "/") path.clear();
            const std::string dir = mount + path;
            if (std::optional<uint64_t> limit = ReadNumber(dir + limitFile); limit && (!best || *limit < best->limit))
                best = CgroupMemory{*limit, ReadNumber(dir + usageFile).value_or(0)};
            if (path.empty()) break;
            path.resize(path.rfind('/'));
        }
    }
    return best;
}

std::optional<uint64_t> AddressSpaceLimit() {
    rlimit limit{};
    if (getrlimit(RLIMIT_AS, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY) return std::nullopt;
    return uint64_t(limit.rlim_cur);
}

void KeepSmaller(std::optional<MemoryFigure>& best, std::optional<uint64_t> bytes, const char* source) {
    if (bytes && (!best || *bytes < best->bytes)) best = MemoryFigure{*bytes, source};
}

}  // namespace

std::optional<MemoryFigure> ProcessMemoryLimit() {
    std::optional<MemoryFigure> best;
    KeepSmaller(best, PhysicalMemoryBytes(), "physical memory");
    if (std::optional<CgroupMemory> cgroup = CgroupLimit()) KeepSmaller(best, cgroup->limit, "cgroup memory limit");
    KeepSmaller(best, AddressSpaceLimit(), "RLIMIT_AS");
    return best;
}

std::optional<MemoryFigure> ProcessAvailableMemory() {
    std::optional<MemoryFigure> best;
    KeepSmaller(best, ReadKilobytes("/proc/meminfo", "MemAvailable"), "available memory");
    if (std::optional<CgroupMemory> cgroup = CgroupLimit())
        KeepSmaller(best, cgroup->limit > cgroup->usage ? cgroup->limit - cgroup->usage : 0, "cgroup memory limit");
    if (std::optional<uint64_t> limit = AddressSpaceLimit()) {
        const uint64_t used = ReadKilobytes("/proc/self/status", "VmSize").value_or(0);
        KeepSmaller(best, *limit > used ? *limit - used : 0, "RLIMIT_AS");
    }
    return best;
}

std::optional<uint64_t> PhysicalMemoryBytes() {
    const long pages = sysconf(_SC_PHYS_PAGES);
    const long pageSize = sysconf(_SC_PAGE_SIZE);
    if (pages <= 0 || pageSize <= 0) return std::nullopt;
    return SaturatingMul(uint64_t(pages), uint64_t(pageSize));
}

std::string FormatGiB(uint64_t bytes) {
    char buffer[64];
    std::snprintf(buffer, sizeof(buffer), "%.1f", double(bytes) / double(uint64_t(1) << 30));
    return buffer;
}

}  // namespace cb
