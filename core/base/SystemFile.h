// What the kernel shows under /proc and /sys (cpuinfo, meminfo, cgroup
// limits): the path policy's reader for files no user names
// (core/base/PathPolicy.h holds the rule for those a user gives). stat gives
// these files no size, so the bound is on what is read.
#pragma once

#include <string>

namespace cb {

// At most this many bytes of a system file are read; a longer one reads as "".
inline constexpr size_t kMaxSystemFileBytes = size_t(4) << 20;

// The text of the system file `path`, or "" when it cannot be read, is not a regular file (opened without
// blocking, checked on the descriptor) or is longer than kMaxSystemFileBytes.
std::string ReadSystemFile(const std::string& path);

}  // namespace cb
