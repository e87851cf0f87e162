// Errors cross the backend interface and the scene loader as values, never as
// exceptions (Amber's Result, Dawn's MaybeError). A Status is "ok or an Error";
// Result<T> is "a T or an Error".
#pragma once

#include <expected>
#include <string>
#include <utility>

namespace cb {

struct Error {
    std::string message;
};

template <typename T>
using Result = std::expected<T, Error>;
using Status = std::expected<void, Error>;

inline std::unexpected<Error> MakeError(std::string message) {
    return std::unexpected<Error>(Error{std::move(message)});
}

}  // namespace cb

// Propagates an error from an expression returning Status or Result<T>.
#define CB_TRY(expr)                                                     \
    do {                                                                 \
        auto cbTryResult_ = (expr);                                      \
        if (!cbTryResult_) return std::unexpected(cbTryResult_.error()); \
    } while (0)
