#include "core/base/Npy.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstring>
#include <filesystem>
#include <sstream>

#include "core/base/PathPolicy.h"

namespace cb {
namespace {

const char* Descr(NpyType type) { return type == NpyType::U8 ? "|u1" : "<f4"; }
size_t ElementBytes(NpyType type) { return type == NpyType::U8 ? 1 : 4; }

}  // namespace

Status WriteNpy(int fd, const std::string& name, NpyType type, std::span<const uint64_t> shape,
                std::span<const std::byte> data) {
    uint64_t count = 1;
    for (uint64_t d : shape) count *= d;
    if (count * ElementBytes(type) != data.size()) return MakeError(name + ": npy data size does not match its shape");

    std::ostringstream dict;
    dict << "{'descr': '" << Descr(type) << "', 'fortran_order': False, 'shape': (";
    for (size_t n = 0; n < shape.size(); ++n)
        dict << shape[n] << (shape.size() == 1 || n + 1 < shape.size() ? ", " : "");
    dict << "), }";
    std::string header = dict.str();
    // magic(6) + version(2) + length(2) + header + '\n' is padded to a multiple of 64.
    size_t total = 10 + header.size() + 1;
    header.append((64 - total % 64) % 64, ' ');
    header.push_back('\n');

    const uint16_t length = static_cast<uint16_t>(header.size());
    const char preamble[10] = {'\x93', 'N', 'U', 'M', 'P', 'Y', 1, 0, char(length & 0xff), char(length >> 8)};
    const std::string_view parts[] = {
        {preamble, sizeof preamble}, header, {reinterpret_cast<const char*>(data.data()), data.size()}};
    for (std::string_view part : parts)
        for (size_t done = 0; done < part.size();) {
            const ssize_t n = ::write(fd, part.data() + done, part.size() - done);
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0) return MakeError(name + ": cannot write: " + std::strerror(n < 0 ? errno : EIO));
            done += size_t(n);
        }
    return {};
}

Status WriteNpy(const std::string& path, NpyType type, std::span<const uint64_t> shape,
                std::span<const std::byte> data) {
    Result<int> opened = OpenAppendFile(path);  // never through a link at `path`, never a FIFO
    if (!opened) return std::unexpected(opened.error());
    const int fd = *opened;
    if (::ftruncate(fd, 0) != 0) {
        const int error = errno;
        ::close(fd);
        return MakeError(path + ": cannot write: " + std::strerror(error));
    }
    Status written = WriteNpy(fd, path, type, shape, data);
    if (::close(fd) != 0 && written) return MakeError(path + ": cannot write: " + std::strerror(errno));
    return written;
}

Result<NpyArray> ReadNpy(const std::string& path) {
    // The whole file, checked as every input is (core/base/PathPolicy.h): a FIFO or a device is refused, not read.
    Result<std::string> file = ReadInputFile(path, kArrayInput);
    if (!file) return std::unexpected(file.error());
    return ParseNpy(*file, path);
}

Result<NpyArray> ParseNpy(const std::string& bytes, const std::string& path) {
    if (bytes.size() < 10 || std::memcmp(bytes.data(), "\x93NUMPY\x01\x00", 8) != 0)
        return MakeError(path + ": not a version 1.0 .npy file");
    const size_t length = uint8_t(bytes[8]) | (size_t(uint8_t(bytes[9])) << 8);
    if (bytes.size() < 10 + length) return MakeError(path + ": truncated .npy header");
    const std::string header = bytes.substr(10, length);

    NpyArray array;
    if (header.find("'descr': '|u1'") != std::string::npos)
        array.type = NpyType::U8;
    else if (header.find("'descr': '<f4'") != std::string::npos)
        array.type = NpyType::F32;
    else
        return MakeError(path + ": unsupported dtype (expected |u1 or <f4)");
    if (header.find("'fortran_order': False") == std::string::npos) return MakeError(path + ": not C order");
    size_t open = header.find("'shape': (");
    size_t close = header.find(')', open);
    if (open == std::string::npos || close == std::string::npos) return MakeError(path + ": no shape in header");
    std::istringstream dims(header.substr(open + 10, close - open - 10));
    // The element count, checked against the data the file holds before anything is allocated for it.
    uint64_t count = 1;
    const uint64_t available = (bytes.size() - 10 - length) / ElementBytes(array.type);
    for (std::string token; std::getline(dims, token, ',');) {
        if (token.find_first_not_of(' ') == std::string::npos) continue;
        const size_t first = token.find_first_not_of(' ');
        const size_t last = token.find_last_not_of(' ');
        uint64_t dim = 0;
        const auto [end, error] = std::from_chars(token.data() + first, token.data() + last + 1, dim);
        if (error != std::errc() || end != token.data() + last + 1)
            return MakeError(path + ": a shape dimension is not a number: '" + token + "'");
        array.shape.push_back(dim);
        count = dim != 0 && count > UINT64_MAX / dim ? UINT64_MAX : count * dim;  // saturating; 0 stays 0
    }
    if (count > available) return MakeError(path + ": truncated .npy data");
    array.data.resize(count * ElementBytes(array.type));
    std::memcpy(array.data.data(), bytes.data() + 10 + length, array.data.size());
    return array;
}

}  // namespace cb
