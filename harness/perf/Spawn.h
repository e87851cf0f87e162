// Runs another cloudbench (this binary or a base/head build) as a child
// process, for `perf record` and `perf compare --interleave`.
#pragma once

#include <string>
#include <vector>

#include "core/base/Error.h"

namespace cb::perf {

// Runs argv[0] (a path; "/proc/self/exe" for this binary) with `argv`, its
// standard output appended to `stdoutPath` ("" = this process's), standard
// error shared, and waits. Returns its exit status, or 128 + the signal that
// killed it. Error: "ARGV0: cannot run: <strerror>". `setEnv` ("NAME=VALUE" each) is the child's
// environment beside this process's: each replaces the variable of its NAME, appended after the rest.
Result<int> RunChild(const std::vector<std::string>& argv, const std::string& stdoutPath,
                     const std::vector<std::string>& setEnv = {});

// This binary's path (readlink of /proc/self/exe).
std::string SelfPath();

}  // namespace cb::perf
