# Every dependency is a Debian 12 package (tools/debian-packages-run.txt, and tools/debian-packages.txt for the
# tests, benchmarks and the sanitized build). A missing
# one stops configure with the package to install.

function(cloudbench_require found name package)
  if(NOT ${found})
    message(FATAL_ERROR "cloudbench needs ${name}, which was not found.\n"
                        "On Debian 12 install it with:  apt-get install ${package}\n"
                        "(or run tools/setup.sh, which installs everything the build needs)")
  endif()
endfunction()

find_package(Threads REQUIRED)

find_package(TBB CONFIG QUIET)
cloudbench_require(TBB_FOUND "oneTBB" libtbb-dev)

# Google Highway: the CPU kernels' SIMD layer and its run-time dispatch (impl_cpu/CpuIsa.h).
find_package(hwy CONFIG QUIET)
cloudbench_require(hwy_FOUND "Google Highway" libhwy-dev)

# OpenVDB, for dump --vdb in the image module: Debian's package has no CMake config of its own, and its
# FindOpenVDB.cmake brings a FindTBB that shadows oneTBB's; the library, the header and Imath (its half type).
find_library(CLOUDBENCH_OPENVDB_LIBRARY openvdb)
find_path(CLOUDBENCH_OPENVDB_INCLUDE openvdb/openvdb.h)
find_library(CLOUDBENCH_IMATH_LIBRARY NAMES Imath-3_1 Imath)
if(CLOUDBENCH_OPENVDB_LIBRARY AND CLOUDBENCH_OPENVDB_INCLUDE AND CLOUDBENCH_IMATH_LIBRARY)
  set(CLOUDBENCH_OPENVDB_FOUND TRUE)
  set(CLOUDBENCH_OPENVDB_LIBRARIES ${CLOUDBENCH_OPENVDB_LIBRARY} ${CLOUDBENCH_IMATH_LIBRARY} TBB::tbb)
endif()
cloudbench_require(CLOUDBENCH_OPENVDB_FOUND "OpenVDB" libopenvdb-dev)

find_package(nlohmann_json CONFIG QUIET)
cloudbench_require(nlohmann_json_FOUND "nlohmann-json" nlohmann-json3-dev)

# Through pkg-config: Debian 12's OpenImageIO CMake config also demands the
# command-line tools (package openimageio-tools), which we do not need.
find_package(PkgConfig QUIET)
cloudbench_require(PKG_CONFIG_FOUND "pkg-config" pkg-config)
pkg_check_modules(OpenImageIO QUIET IMPORTED_TARGET OpenImageIO)
cloudbench_require(OpenImageIO_FOUND "OpenImageIO" libopenimageio-dev)

if(CLOUDBENCH_BUILD_TESTS)
  find_package(GTest CONFIG QUIET)
  cloudbench_require(GTest_FOUND "GoogleTest" libgtest-dev)
endif()

if(CLOUDBENCH_BUILD_BENCHMARKS)
  find_package(benchmark CONFIG QUIET)
  cloudbench_require(benchmark_FOUND "Google Benchmark" libbenchmark-dev)
endif()

# The exact attenuation reference (SPEC 11). Debian's embree-config.cmake defines
# the imported target `embree`.
find_package(embree 3 CONFIG QUIET)
cloudbench_require(embree_FOUND "Embree 3" libembree-dev)
