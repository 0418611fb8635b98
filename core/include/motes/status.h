// Error reporting across the public API and the backend interface: Status and Result<T>.
#pragma once

#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include "motes/api.h"

MOTES_API_BEGIN
namespace motes {

/// Outcome of an operation: ok, or a message written for the user.
class Status {
 public:
  Status() = default;
  static Status ok() { return Status(); }
  static Status error(std::string message) { return Status(std::move(message)); }

  [[nodiscard]] bool is_ok() const { return !message_.has_value(); }
  explicit operator bool() const { return is_ok(); }
  /// The message; empty when ok.
  [[nodiscard]] const std::string& message() const {
    static const std::string empty;
    return message_ ? *message_ : empty;
  }

 private:
  explicit Status(std::string message) : message_(std::move(message)) {}
  std::optional<std::string> message_;
};

/// A value, or the Status that says why there is none.
template <typename T>
class Result {
 public:
  Result(T value) : value_(std::move(value)) {}         // NOLINT(google-explicit-constructor)
  Result(Status status) : status_(std::move(status)) {  // NOLINT(google-explicit-constructor)
    if (status_.is_ok()) status_ = Status::error("internal error: Result built from an ok Status");
  }

  [[nodiscard]] bool is_ok() const { return value_.has_value(); }
  explicit operator bool() const { return is_ok(); }
  [[nodiscard]] const Status& status() const { return status_; }
  [[nodiscard]] const std::string& message() const { return status_.message(); }

  T& value() & {
    if (!value_) throw std::logic_error("Result::value() on an error: " + status_.message());
    return *value_;
  }
  const T& value() const& {
    if (!value_) throw std::logic_error("Result::value() on an error: " + status_.message());
    return *value_;
  }
  /// By value, so that a line such as `for (auto& p : sim.snapshot().value().particle_pos)` is
  /// safe: a reference into the temporary Result would dangle there (C++20 does not extend the
  /// Result's life through a call).
  T value() && {
    if (!value_) throw std::logic_error("Result::value() on an error: " + status_.message());
    return std::move(*value_);
  }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }
  T& operator*() & { return value(); }

 private:
  std::optional<T> value_;
  Status status_;
};

/// Exception used inside the library's loaders; converted to Status at the API boundary.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace motes
MOTES_API_END
