// Small POSIX helpers shared by the harness's process and file code.
#pragma once

#include <unistd.h>

#include <cerrno>
#include <string_view>

namespace cb {

// Writes all of `text` to `fd`, retrying short writes and EINTR. On failure
// returns false with errno set (EIO when the descriptor accepted nothing).
inline bool WriteAll(int fd, std::string_view text) {
    for (size_t done = 0; done < text.size();) {
        const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            if (n == 0) errno = EIO;
            return false;
        }
        done += size_t(n);
    }
    return true;
}

}  // namespace cb
