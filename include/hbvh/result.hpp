// SPDX-License-Identifier: MIT
// Result<T>: a value or an Error that says where bad input came from.
#pragma once

#include <string>
#include <utility>
#include <variant>

namespace hbvh {

/// What went wrong with input from outside, and where: file and line when known, or a primitive index.
struct Error {
    std::string message;  ///< The problem, in words a user understands.
    std::string file;     ///< Source name ("-" for stdin); empty when not from a file.
    int line = 0;         ///< 1-based line, 0 when unknown.

    Error(std::string message_text, std::string file_name = {}, int line_number = 0)
        : message(std::move(message_text)), file(std::move(file_name)), line(line_number) {}

    /// "file:line: message", leaving out the parts that are unknown.
    [[nodiscard]] std::string to_string() const {
        std::string where = file;
        if (line > 0) where += (where.empty() ? "line " : ":") + std::to_string(line);
        return where.empty() ? message : where + ": " + message;
    }
};

/// Either a T or an Error. Check has_value() before value(); error() on a value is a bug.
template <class T>
class [[nodiscard]] Result {
public:
    Result(T value) : state_(std::move(value)) {}
    Result(Error error) : state_(std::move(error)) {}

    [[nodiscard]] bool has_value() const { return state_.index() == 0; }
    explicit operator bool() const { return has_value(); }
    [[nodiscard]] T& value() & { return std::get<0>(state_); }
    [[nodiscard]] const T& value() const& { return std::get<0>(state_); }
    [[nodiscard]] T&& value() && { return std::get<0>(std::move(state_)); }
    [[nodiscard]] const Error& error() const { return std::get<1>(state_); }
    T* operator->() { return &value(); }
    const T* operator->() const { return &value(); }
    T& operator*() & { return value(); }
    const T& operator*() const& { return value(); }

private:
    std::variant<T, Error> state_;
};

/// Result of an operation that returns nothing on success.
struct Ok {};
using Status = Result<Ok>;

}  // namespace hbvh
