#include "io/xml.h"

#include <cstdint>

namespace afmb {

const XmlAttribute *XmlElement::attribute(std::string_view n) const {
  for (const XmlAttribute &a : attributes)
    if (a.name == n) return &a;
  return nullptr;
}

const XmlElement *XmlElement::child(std::string_view n) const {
  for (const XmlElement &c : children)
    if (c.name == n) return &c;
  return nullptr;
}

namespace {

constexpr int kMaxDepth = 256;  // bounds the recursion on hostile input

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

// Bytes >= 0x80 are taken as name characters so UTF-8 names pass through.
bool is_name_start(char c) {
  unsigned char u = static_cast<unsigned char>(c);
  return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || c == '_' || c == ':' || u >= 0x80;
}
bool is_name_char(char c) {
  return is_name_start(c) || (c >= '0' && c <= '9') || c == '-' || c == '.';
}

void append_utf8(std::string &out, uint32_t cp) {
  if (cp < 0x80) {
    out += static_cast<char>(cp);
  } else if (cp < 0x800) {
    out += static_cast<char>(0xC0 | (cp >> 6));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  } else if (cp < 0x10000) {
    out += static_cast<char>(0xE0 | (cp >> 12));
    out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  } else {
    out += static_cast<char>(0xF0 | (cp >> 18));
    out += static_cast<char>(0x80 | ((cp >> 12) & 0x3F));
    out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  }
}

class Parser {
 public:
  Parser(std::string_view text, const std::string &source) : t_(text), source_(source) {}

  Expected<XmlElement> parse_document() {
    if (starts("\xEF\xBB\xBF")) pos_ += 3;
    if (starts("<?xml") && pos_ + 5 < t_.size() && (is_space(t_[pos_ + 5]) || t_[pos_ + 5] == '?')) {
      Status s = skip_until("?>", "XML declaration");
      if (!s) return s;
    }
    // Prolog: blanks, comments and processing instructions before the root.
    for (;;) {
      skip_spaces();
      if (at_end()) return fail("no root element");
      Status s = skip_misc();
      if (!s) return s;
      if (misc_skipped_) continue;
      if (t_[pos_] != '<') return fail("text before the root element");
      break;
    }
    XmlElement root;
    Status s = parse_element(root, 1);
    if (!s) return s;
    // Epilog: only blanks, comments and processing instructions.
    for (;;) {
      skip_spaces();
      if (at_end()) break;
      s = skip_misc();
      if (!s) return s;
      if (misc_skipped_) continue;
      return fail(t_[pos_] == '<' ? "a second element after the root element <" + root.name + ">"
                                  : "text after the root element <" + root.name + ">");
    }
    return root;
  }

 private:
  bool at_end() const { return pos_ >= t_.size(); }
  bool starts(std::string_view s) const { return t_.substr(pos_, s.size()) == s; }
  void advance(size_t n = 1) {
    for (size_t i = 0; i < n && pos_ < t_.size(); ++i)
      if (t_[pos_++] == '\n') ++line_;
  }
  void skip_spaces() {
    while (!at_end() && is_space(t_[pos_])) advance();
  }
  Status fail(const std::string &message, int line = 0) const {
    return Status::error(source_ + ":" + std::to_string(line ? line : line_) + ": " + message);
  }

  // Skips past `end`; `what` names the construct if the text ends first.
  Status skip_until(std::string_view end, const char *what) {
    int start = line_;
    size_t at = t_.find(end, pos_);
    if (at == std::string_view::npos)
      return fail(std::string("unterminated ") + what + " (opened here)", start);
    advance(at + end.size() - pos_);
    return Status::ok();
  }

  // Skips one comment or processing instruction at pos_; sets misc_skipped_.
  Status skip_misc() {
    misc_skipped_ = false;
    if (starts("<!--")) {
      misc_skipped_ = true;
      return skip_until("-->", "comment");
    }
    if (starts("<!DOCTYPE")) return fail("DOCTYPE declarations are not supported");
    if (starts("<?xml") && pos_ + 5 < t_.size() && (is_space(t_[pos_ + 5]) || t_[pos_ + 5] == '?'))
      return fail("XML declaration not at the start of the document");
    if (starts("<?")) {
      misc_skipped_ = true;
      return skip_until("?>", "processing instruction");
    }
    return Status::ok();
  }

  bool read_name(std::string &out) {
    if (at_end() || !is_name_start(t_[pos_])) return false;
    size_t start = pos_;
    while (!at_end() && is_name_char(t_[pos_])) ++pos_;  // names hold no newline
    out.assign(t_.substr(start, pos_ - start));
    return true;
  }

  // Decodes the entity at pos_ ('&') into out.
  Status read_entity(std::string &out) {
    size_t semi = t_.find(';', pos_);
    size_t nl = t_.find('\n', pos_);
    if (semi == std::string_view::npos || semi - pos_ > 12 || (nl != std::string_view::npos && nl < semi))
      return fail("'&' does not start an entity (write &amp;)");
    std::string_view name = t_.substr(pos_ + 1, semi - pos_ - 1);
    if (name == "lt") out += '<';
    else if (name == "gt") out += '>';
    else if (name == "amp") out += '&';
    else if (name == "quot") out += '"';
    else if (name == "apos") out += '\'';
    else if (name.size() >= 2 && name[0] == '#') {
      bool hex = name[1] == 'x';
      std::string_view digits = name.substr(hex ? 2 : 1);
      if (digits.empty() || digits.size() > 8) return fail("bad character reference &" + std::string(name) + ";");
      uint32_t cp = 0;
      for (char c : digits) {
        int d;
        if (c >= '0' && c <= '9') d = c - '0';
        else if (hex && c >= 'a' && c <= 'f') d = c - 'a' + 10;
        else if (hex && c >= 'A' && c <= 'F') d = c - 'A' + 10;
        else return fail("bad character reference &" + std::string(name) + ";");
        cp = cp * (hex ? 16 : 10) + static_cast<uint32_t>(d);
      }
      if (cp == 0 || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF))
        return fail("character reference &" + std::string(name) + "; is not a character");
      append_utf8(out, cp);
    } else {
      return fail("unknown entity &" + std::string(name) + ";");
    }
    advance(semi + 1 - pos_);
    return Status::ok();
  }

  Status parse_attributes(XmlElement &el, bool *empty) {
    for (;;) {
      bool spaced = !at_end() && is_space(t_[pos_]);
      skip_spaces();
      if (at_end()) return fail("end of file inside the tag <" + el.name + ">", el.line);
      if (starts("/>")) {
        advance(2);
        *empty = true;
        return Status::ok();
      }
      if (t_[pos_] == '>') {
        advance();
        *empty = false;
        return Status::ok();
      }
      XmlAttribute a;
      a.line = line_;
      if (!read_name(a.name))
        return fail("unexpected '" + std::string(1, t_[pos_]) + "' in the tag <" + el.name + ">");
      if (!spaced) return fail("attribute '" + a.name + "' not separated by a blank in <" + el.name + ">");
      skip_spaces();
      if (at_end() || t_[pos_] != '=')
        return fail("attribute '" + a.name + "' of <" + el.name + "> has no '=' and value");
      advance();
      skip_spaces();
      if (at_end() || (t_[pos_] != '"' && t_[pos_] != '\''))
        return fail("value of attribute '" + a.name + "' of <" + el.name + "> is not quoted");
      char quote = t_[pos_];
      advance();
      for (;;) {
        if (at_end()) return fail("unterminated value of attribute '" + a.name + "'", a.line);
        char c = t_[pos_];
        if (c == quote) {
          advance();
          break;
        }
        if (c == '<') return fail("'<' in the value of attribute '" + a.name + "' (write &lt;)");
        if (c == '&') {
          Status s = read_entity(a.value);
          if (!s) return s;
          continue;
        }
        a.value += is_space(c) ? ' ' : c;  // attribute-value normalisation
        advance();
      }
      if (el.attribute(a.name)) return fail("duplicate attribute '" + a.name + "' in <" + el.name + ">");
      el.attributes.push_back(std::move(a));
    }
  }

  Status parse_element(XmlElement &el, int depth) {
    if (depth > kMaxDepth) return fail("elements nested deeper than " + std::to_string(kMaxDepth));
    el.line = line_;
    advance();  // '<'
    if (!read_name(el.name)) return fail("expected an element name after '<'");
    bool empty = false;
    Status s = parse_attributes(el, &empty);
    if (!s || empty) return s;
    for (;;) {
      if (at_end())
        return fail("end of file inside <" + el.name + "> opened at line " + std::to_string(el.line));
      char c = t_[pos_];
      if (c == '&') {
        s = read_entity(el.text);
        if (!s) return s;
        continue;
      }
      if (c != '<') {
        el.text += c;
        advance();
        continue;
      }
      if (starts("</")) {
        int end_line = line_;
        advance(2);
        std::string name;
        if (!read_name(name)) return fail("expected an element name after '</'");
        skip_spaces();
        if (at_end() || t_[pos_] != '>') return fail("end tag </" + name + "> has no '>'", end_line);
        advance();
        if (name != el.name)
          return fail("</" + name + "> closes <" + el.name + "> opened at line " + std::to_string(el.line),
                      end_line);
        return Status::ok();
      }
      if (starts("<![CDATA[")) {
        advance(9);
        size_t at = t_.find("]]>", pos_);
        if (at == std::string_view::npos) return fail("unterminated CDATA section");
        el.text.append(t_.substr(pos_, at - pos_));
        advance(at + 3 - pos_);
        continue;
      }
      s = skip_misc();
      if (!s) return s;
      if (misc_skipped_) continue;
      if (starts("<!")) return fail("unexpected '<!' markup inside <" + el.name + ">");
      XmlElement child;
      s = parse_element(child, depth + 1);
      if (!s) return s;
      el.children.push_back(std::move(child));
    }
  }

  std::string_view t_;
  const std::string &source_;
  size_t pos_ = 0;
  int line_ = 1;
  bool misc_skipped_ = false;
};

}  // namespace

Expected<XmlElement> parse_xml(std::string_view text, const std::string &source_name) {
  Parser p(text, source_name);
  return p.parse_document();
}

}  // namespace afmb
