// The .npy writer: header layout (NumPy format 1.0) and a round trip.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>

#include "core/base/Npy.h"

namespace cb {
namespace {

// Test the header byte for byte for a small float array: magic, version 1.0,
// the dict, padding so that the data starts at a multiple of 64. The dict is 62
// characters, so 10 + 62 + 1 = 73 bytes pad to 128: a header length of 118.
TEST(Npy, HeaderLayout) {
    const std::string path = ::testing::TempDir() + "/h.npy";
    const float data[6] = {1, 2, 3, 4, 5, 6};
    const uint64_t shape[3] = {1, 2, 3};
    ASSERT_TRUE(WriteNpy(path, NpyType::F32, shape, std::as_bytes(std::span(data))));
    std::ifstream in(path, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    ASSERT_EQ(bytes.size(), 128u + 24u);
    EXPECT_EQ(bytes.substr(0, 6), "\x93NUMPY");
    EXPECT_EQ(bytes[6], 1);
    EXPECT_EQ(bytes[7], 0);
    EXPECT_EQ(uint8_t(bytes[8]) | (uint8_t(bytes[9]) << 8), 118);
    EXPECT_EQ(bytes.substr(10, 63).find("{'descr': '<f4', 'fortran_order': False, 'shape': (1, 2, 3), }"), 0u);
    EXPECT_EQ(bytes[127], '\n');
    EXPECT_EQ(bytes[126], ' ');
    float first;
    std::memcpy(&first, bytes.data() + 128, 4);
    EXPECT_EQ(first, 1.0f);
}

// Test that ReadNpy returns what WriteNpy wrote, and that a one-dimensional
// shape keeps its trailing comma.
TEST(Npy, RoundTrip) {
    const std::string path = ::testing::TempDir() + "/r.npy";
    std::vector<uint8_t> data = {0, 1, 1, 0, 255};
    const uint64_t shape[1] = {5};
    ASSERT_TRUE(WriteNpy(path, NpyType::U8, shape, std::as_bytes(std::span(data))));
    auto read = ReadNpy(path);
    ASSERT_TRUE(read.has_value()) << read.error().message;
    EXPECT_EQ(read->type, NpyType::U8);
    EXPECT_EQ(read->shape, std::vector<uint64_t>{5});
    ASSERT_EQ(read->data.size(), 5u);
    EXPECT_EQ(std::memcmp(read->data.data(), data.data(), 5), 0);
}

// Test that a size mismatch is refused rather than written.
TEST(Npy, RefusesWrongSize) {
    const uint64_t shape[2] = {2, 2};
    const uint8_t data[3] = {};
    EXPECT_FALSE(WriteNpy(::testing::TempDir() + "/bad.npy", NpyType::U8, shape, std::as_bytes(std::span(data))));
}

}  // namespace
}  // namespace cb
