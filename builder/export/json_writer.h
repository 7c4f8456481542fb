// A small JSON writer for the glTF exporter: compact output (no spaces),
// strings escaped per RFC 8259, numbers in their shortest round-trip form.
//
// Calls must nest properly: inside an object, key() before every value.
// Misuse (a value without a key, unbalanced ends) is a programming error
// and asserts. Non-finite numbers have no JSON form: they set failed() and
// are written as 0, so the caller can refuse the output.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace afmb {

class JsonWriter {
 public:
  JsonWriter &begin_object();
  JsonWriter &end_object();
  JsonWriter &begin_array();
  JsonWriter &end_array();
  JsonWriter &key(std::string_view name);
  JsonWriter &value(std::string_view text);
  JsonWriter &value(const char *text) { return value(std::string_view(text)); }
  JsonWriter &value(double number);
  JsonWriter &value(int64_t number);
  JsonWriter &value(int number) { return value(int64_t(number)); }
  JsonWriter &value(uint32_t number) { return value(int64_t(number)); }
  JsonWriter &value(size_t number) { return value(int64_t(number)); }
  JsonWriter &value(bool flag);
  // key(name).value(v) in one call.
  template <class T>
  JsonWriter &field(std::string_view name, const T &v) {
    return key(name).value(v);
  }
  // An array of numbers.
  JsonWriter &numbers(const double *v, size_t n);

  const std::string &text() const { return out_; }
  bool complete() const { return stack_.empty() && !out_.empty(); }
  bool failed() const { return failed_; }

 private:
  void before_value();
  void put_string(std::string_view s);

  std::string out_;
  // One entry per open container: 'o' object, 'a' array; `first_` says
  // whether it holds nothing yet.
  std::vector<char> stack_;
  std::vector<bool> first_;
  bool after_key_ = false;
  bool failed_ = false;
};

}  // namespace afmb
