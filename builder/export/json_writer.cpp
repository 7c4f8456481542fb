#include "export/json_writer.h"

#include <cassert>
#include <charconv>
#include <cmath>

namespace afmb {

void JsonWriter::before_value() {
  if (after_key_) {
    after_key_ = false;
    return;
  }
  assert((stack_.empty() ? out_.empty() : stack_.back() == 'a') && "a value needs a key here");
  if (!stack_.empty()) {
    if (!first_.back()) out_ += ',';
    first_.back() = false;
  }
}

JsonWriter &JsonWriter::begin_object() {
  before_value();
  out_ += '{';
  stack_.push_back('o');
  first_.push_back(true);
  return *this;
}

JsonWriter &JsonWriter::end_object() {
  assert(!stack_.empty() && stack_.back() == 'o' && !after_key_);
  stack_.pop_back();
  first_.pop_back();
  out_ += '}';
  return *this;
}

JsonWriter &JsonWriter::begin_array() {
  before_value();
  out_ += '[';
  stack_.push_back('a');
  first_.push_back(true);
  return *this;
}

JsonWriter &JsonWriter::end_array() {
  assert(!stack_.empty() && stack_.back() == 'a');
  stack_.pop_back();
  first_.pop_back();
  out_ += ']';
  return *this;
}

JsonWriter &JsonWriter::key(std::string_view name) {
  assert(!stack_.empty() && stack_.back() == 'o' && !after_key_);
  if (!first_.back()) out_ += ',';
  first_.back() = false;
  put_string(name);
  out_ += ':';
  after_key_ = true;
  return *this;
}

void JsonWriter::put_string(std::string_view s) {
  static const char hex[] = "0123456789abcdef";
  out_ += '"';
  for (char ch : s) {
    const unsigned char c = static_cast<unsigned char>(ch);
    switch (c) {
      case '"': out_ += "\\\""; break;
      case '\\': out_ += "\\\\"; break;
      case '\n': out_ += "\\n"; break;
      case '\r': out_ += "\\r"; break;
      case '\t': out_ += "\\t"; break;
      default:
        if (c < 0x20) {
          out_ += "\\u00";
          out_ += hex[c >> 4];
          out_ += hex[c & 15];
        } else {
          out_ += ch;  // UTF-8 passes through
        }
    }
  }
  out_ += '"';
}

JsonWriter &JsonWriter::value(std::string_view text) {
  before_value();
  put_string(text);
  return *this;
}

JsonWriter &JsonWriter::value(double number) {
  before_value();
  if (!std::isfinite(number)) {
    failed_ = true;
    number = 0;
  }
  if (number == 0) number = 0;  // no "-0"
  char buf[32];
  const std::to_chars_result r = std::to_chars(buf, buf + sizeof buf, number);
  assert(r.ec == std::errc());
  out_.append(buf, r.ptr);
  return *this;
}

JsonWriter &JsonWriter::value(int64_t number) {
  before_value();
  out_ += std::to_string(number);
  return *this;
}

JsonWriter &JsonWriter::value(bool flag) {
  before_value();
  out_ += flag ? "true" : "false";
  return *this;
}

JsonWriter &JsonWriter::numbers(const double *v, size_t n) {
  begin_array();
  for (size_t i = 0; i < n; ++i) value(v[i]);
  return end_array();
}

}  // namespace afmb
