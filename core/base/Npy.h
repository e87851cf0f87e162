// NumPy .npy (format version 1.0) writing and reading for the canonical dumps:
// C order, little-endian, shape as given (the dumps use (nz, ny, nx)).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/base/Error.h"

namespace cb {

enum class NpyType : uint8_t { U8, F32 };

// Writes the array through `fd` (open for writing, at its start); `name` is
// the file's name in messages: "NAME: cannot write: <strerror>".
Status WriteNpy(int fd, const std::string& name, NpyType type, std::span<const uint64_t> shape,
                std::span<const std::byte> data);
// Creates or truncates `path` (never through a symbolic link at `path`: O_NOFOLLOW) and writes the array.
Status WriteNpy(const std::string& path, NpyType type, std::span<const uint64_t> shape,
                std::span<const std::byte> data);

struct NpyArray {
    NpyType type = NpyType::U8;
    std::vector<uint64_t> shape;
    std::vector<std::byte> data;
};

// Reads what WriteNpy writes (|u1 or <f4, C order); anything else is an error.
Result<NpyArray> ReadNpy(const std::string& path);
// The array whose file's bytes are `bytes`; `path` names the file in errors.
Result<NpyArray> ParseNpy(const std::string& bytes, const std::string& path);

}  // namespace cb
