// The "overloaded" visitor for std::visit: Overloaded{[](const A&) {...}, [](const B&) {...}}.
#pragma once

namespace cb {

template <class... Fs>
struct Overloaded : Fs... {
    using Fs::operator()...;
};
// Spelled out for clang 16 (the sanitized build), which lacks aggregate deduction (P1816).
template <typename... Fs>
Overloaded(Fs...) -> Overloaded<Fs...>;

}  // namespace cb
