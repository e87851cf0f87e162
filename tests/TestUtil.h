// Helpers shared by the tests: canonical upload/download through a backend.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "core/Backend.h"

namespace cb::test {

inline std::unique_ptr<Buffer> MakeBuffer(Backend& backend, BufferFormat format, Extent3 extent) {
    auto buffer = backend.CreateBuffer(format, extent);
    EXPECT_TRUE(buffer.has_value()) << buffer.error().message;
    return std::move(*buffer);
}

template <typename T>
std::unique_ptr<Buffer> MakeFilled(Backend& backend, BufferFormat format, Extent3 extent, const std::vector<T>& data) {
    auto buffer = MakeBuffer(backend, format, extent);
    Status status = backend.Upload(*buffer, std::as_bytes(std::span(data)));
    EXPECT_TRUE(status.has_value()) << status.error().message;
    return buffer;
}

template <typename T>
std::vector<T> Read(Backend& backend, const Buffer& buffer) {
    std::vector<T> data(buffer.CanonicalBytes() / sizeof(T));
    Status status = backend.Download(buffer, std::as_writable_bytes(std::span(data)));
    EXPECT_TRUE(status.has_value()) << status.error().message;
    return data;
}

}  // namespace cb::test
