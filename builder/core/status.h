// Status and Expected<T>: the error type at every builder boundary.
//
// A failed operation carries one human-readable message that already names
// where the problem is ("song.WRL:1733: coordIndex 9999 out of range (2916
// points)"). Callers add context with Status::wrap() rather than re-wording.
// No exceptions cross a builder boundary.
#pragma once

#include <cassert>
#include <optional>
#include <string>
#include <utility>

namespace afmb {

class Status {
 public:
  Status() = default;  // success
  static Status ok() { return Status(); }
  static Status error(std::string message) {
    Status s;
    s.failed_ = true;
    s.message_ = std::move(message);
    return s;
  }

  bool is_ok() const { return !failed_; }
  explicit operator bool() const { return !failed_; }
  const std::string &message() const { return message_; }

  // Prefixes the message with context, e.g. wrap("song.fdp") gives
  // "song.fdp: <message>". No effect on success.
  Status wrap(const std::string &context) const {
    if (!failed_) return *this;
    return error(context + ": " + message_);
  }

 private:
  bool failed_ = false;
  std::string message_;
};

// Either a value or a failed Status.
template <class T>
class Expected {
 public:
  Expected(T value) : value_(std::move(value)) {}  // NOLINT: implicit by design
  Expected(Status status) : status_(std::move(status)) {  // NOLINT
    assert(!status_.is_ok() && "Expected built from an ok Status");
  }

  bool is_ok() const { return value_.has_value(); }
  explicit operator bool() const { return value_.has_value(); }
  const Status &status() const { return status_; }

  T &value() & { assert(value_); return *value_; }
  const T &value() const & { assert(value_); return *value_; }
  T &&value() && { assert(value_); return std::move(*value_); }
  T *operator->() { return &value(); }
  const T *operator->() const { return &value(); }
  T &operator*() { return value(); }
  const T &operator*() const { return value(); }

 private:
  std::optional<T> value_;
  Status status_;
};

}  // namespace afmb
