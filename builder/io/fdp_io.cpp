#include "io/fdp_io.h"

#include <charconv>
#include <cmath>
#include <map>
#include <utility>
#include <vector>

#include "core/atomic_file.h"
#include "io/xml.h"

namespace afmb {

namespace {

// ---- small parsing helpers ---------------------------------------------------

std::string at(const std::string &source, int line) {
  return line > 0 ? source + ":" + std::to_string(line) : source;
}

Status error_at(const std::string &source, int line, const std::string &message) {
  return Status::error(at(source, line) + ": " + message);
}

// A finite decimal number, the whole of `s` ("1e-3" yes; "+1", "nan", "0x1" no).
bool parse_number(std::string_view s, double *out) {
  if (s.empty()) return false;
  double v = 0;
  auto r = std::from_chars(s.data(), s.data() + s.size(), v, std::chars_format::general);
  if (r.ec != std::errc() || r.ptr != s.data() + s.size() || !std::isfinite(v)) return false;
  *out = v;
  return true;
}

// A non-negative decimal integer below 2^31, the whole of `s`.
bool parse_index(std::string_view s, int *out) {
  if (s.empty() || s.size() > 10) return false;
  for (char c : s)
    if (c < '0' || c > '9') return false;
  long v = 0;
  for (char c : s) v = v * 10 + (c - '0');
  if (v > 0x7FFFFFFFL) return false;
  *out = static_cast<int>(v);
  return true;
}

std::string quoted(std::string_view s) {
  const size_t kMax = 40;
  if (s.size() > kMax) return "'" + std::string(s.substr(0, kMax)) + "...'";
  return "'" + std::string(s) + "'";
}

std::string unknown_fdp(std::string_view name) {
  return "unknown FDP " + quoted(name) + " (not one of the 84 MPEG-4 feature points 2.1 ... 11.6)";
}

// Splits text into lines (LF or CRLF) and each line into blank-separated
// tokens; a token starting with '#' ends the line (comment).
struct TextLine {
  int number = 0;
  std::vector<std::string_view> tokens;
};

std::vector<TextLine> tokenize(std::string_view text) {
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);
  std::vector<TextLine> lines;
  int number = 0;
  size_t pos = 0;
  while (pos <= text.size()) {
    size_t nl = text.find('\n', pos);
    std::string_view line = text.substr(pos, nl == std::string_view::npos ? std::string_view::npos : nl - pos);
    ++number;
    TextLine tl;
    tl.number = number;
    size_t i = 0;
    while (i < line.size()) {
      while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
      if (i >= line.size() || line[i] == '#') break;
      size_t start = i;
      while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r') ++i;
      tl.tokens.push_back(line.substr(start, i - start));
    }
    if (!tl.tokens.empty()) lines.push_back(std::move(tl));
    if (nl == std::string_view::npos) break;
    pos = nl + 1;
  }
  return lines;
}

// Rejects a second point for the same FDP on the same part (or a second free
// point for the same FDP): the file would be ambiguous.
class DuplicateCheck {
 public:
  Status add(const FdpSet &set, const FdpPoint &p) {
    auto key = std::make_pair(p.id, p.part_name);
    auto it = first_.find(key);
    if (it == first_.end()) {
      first_.emplace(key, p.line);
      return Status::ok();
    }
    std::string what = p.part_name.empty() ? "as a free point" : "on part '" + p.part_name + "'";
    return Status::error(fdp_location(set, p) + ": given twice " + what + " (first at line " +
                         std::to_string(it->second) + ")");
  }

 private:
  std::map<std::pair<FdpId, std::string>, int> first_;
};

Status no_points(const std::string &source) {
  return Status::error(source + ": no feature points");
}

// ---- XfaceEd XML -------------------------------------------------------------

Expected<FdpSet> parse_xfaceed(std::string_view text, const std::string &source) {
  Expected<XmlElement> doc = parse_xml(text, source);
  if (!doc) return doc.status();
  const XmlElement &root = *doc;
  if (root.name != "xfdp")
    return error_at(source, root.line, "root element is <" + root.name + ">, not <xfdp>: not an XfaceEd FDP file");

  FdpSet set;
  set.source = source;
  if (const XmlElement *head = root.child("head")) {
    if (const XmlElement *fa = head->child("fapu")) {
      static const char *const kNames[5] = {"ES0", "IRISD0", "ENS0", "MNS0", "MW0"};
      double v[5];
      for (int k = 0; k < 5; ++k) {
        const XmlAttribute *a = fa->attribute(kNames[k]);
        if (!a) return error_at(source, fa->line, std::string("<fapu> has no ") + kNames[k] + " attribute");
        if (!parse_number(a->value, &v[k]) || v[k] <= 0)
          return error_at(source, a->line, std::string("<fapu> ") + kNames[k] + "=" + quoted(a->value) +
                                               " is not a positive number");
      }
      set.stored_fapu = Fapu{v[0], v[1], v[2], v[3], v[4]};
    }
  }

  DuplicateCheck dups;
  for (const XmlElement &e : root.children) {
    if (e.name != "fdp") continue;
    const XmlAttribute *name = e.attribute("name");
    if (!name) return error_at(source, e.line, "<fdp> has no 'name' attribute");
    std::optional<FdpId> id = FdpId::parse(name->value);
    if (!id) return error_at(source, name->line, "<fdp name=" + quoted(name->value) + ">: " + unknown_fdp(name->value));
    FdpPoint p;
    p.id = *id;
    p.line = e.line;
    const XmlAttribute *index = e.attribute("index");
    const XmlAttribute *affects = e.attribute("affects");
    if (!index) return Status::error(fdp_location(set, p) + ": <fdp> has no 'index' attribute");
    if (!parse_index(index->value, &p.vertex)) {
      p.line = index->line;
      return Status::error(fdp_location(set, p) + ": index=" + quoted(index->value) +
                           " is not a vertex index (a non-negative integer)");
    }
    if (!affects) return Status::error(fdp_location(set, p) + ": <fdp> has no 'affects' attribute");
    if (affects->value.empty()) {
      p.line = affects->line;
      return Status::error(fdp_location(set, p) + ": affects=\"\" names no part");
    }
    p.part_name = affects->value;
    Status s = dups.add(set, p);
    if (!s) return s;
    set.points.push_back(std::move(p));
  }
  if (set.points.empty()) return error_at(source, root.line, "no <fdp> elements in <xfdp>");
  return set;
}

// ---- plain text form ---------------------------------------------------------

Expected<FdpSet> parse_text_form(std::string_view text, const std::string &source) {
  FdpSet set;
  set.source = source;
  DuplicateCheck dups;
  int fapu_line = 0;
  for (const TextLine &l : tokenize(text)) {
    const auto &t = l.tokens;
    if (t[0] == "fapu") {
      if (fapu_line)
        return error_at(source, l.number, "second fapu line (the first is line " + std::to_string(fapu_line) + ")");
      if (t.size() != 6)
        return error_at(source, l.number, "expected 'fapu ES0 IRISD0 ENS0 MNS0 MW0', found " +
                                              std::to_string(t.size() - 1) + " values");
      static const char *const kNames[5] = {"ES0", "IRISD0", "ENS0", "MNS0", "MW0"};
      double v[5];
      for (int k = 0; k < 5; ++k)
        if (!parse_number(t[k + 1], &v[k]) || v[k] <= 0)
          return error_at(source, l.number, std::string("fapu ") + kNames[k] + " " + quoted(t[k + 1]) +
                                                " is not a positive number");
      set.stored_fapu = Fapu{v[0], v[1], v[2], v[3], v[4]};
      fapu_line = l.number;
      continue;
    }
    std::optional<FdpId> id = FdpId::parse(t[0]);
    if (!id) return error_at(source, l.number, unknown_fdp(t[0]));
    FdpPoint p;
    p.id = *id;
    p.line = l.number;
    if (t.size() == 3) {
      p.part_name = std::string(t[1]);
      if (!parse_index(t[2], &p.vertex))
        return Status::error(fdp_location(set, p) + ": vertex " + quoted(t[2]) +
                             " is not a vertex index (a non-negative integer)");
    } else if (t.size() == 4) {
      for (int k = 0; k < 3; ++k)
        if (!parse_number(t[k + 1], &p.pos[k]))
          return Status::error(fdp_location(set, p) + ": coordinate " + "xyz"[k] + " " + quoted(t[k + 1]) +
                               " is not a number");
    } else {
      return Status::error(fdp_location(set, p) + ": expected 'FDP PART VERTEX' or 'FDP X Y Z', found " +
                           std::to_string(t.size()) + " fields");
    }
    Status s = dups.add(set, p);
    if (!s) return s;
    set.points.push_back(std::move(p));
  }
  if (set.points.empty()) return no_points(source);
  return set;
}

// ---- visage line form --------------------------------------------------------

// "G.I" with canonical decimal G and I (the visage point name syntax, groups
// 2..17); false when `s` is not of that shape.
bool split_point_name(std::string_view s, int *g, int *i) {
  size_t dot = s.find('.');
  if (dot == std::string_view::npos) return false;
  std::string_view a = s.substr(0, dot), b = s.substr(dot + 1);
  if ((a.size() > 1 && a[0] == '0') || (b.size() > 1 && b[0] == '0')) return false;
  return parse_index(a, g) && parse_index(b, i);
}

Expected<FdpSet> parse_visage(std::string_view text, const std::string &source) {
  FdpSet set;
  set.source = source;
  std::map<FdpId, int> first_line;  // the SDK keeps one point per FDP
  bool first = true;
  for (const TextLine &l : tokenize(text)) {
    const auto &t = l.tokens;
    int g = 0, i = 0;
    bool point = split_point_name(t[0], &g, &i) && g >= 2;
    double v;
    if (first && (!point || (t.size() >= 2 && !parse_number(t[1], &v)))) {
      // Header: "<version> <model file> <numbers...>", e.g. "1.0 candide3.fdp 0 0 0 0 0 0";
      // told from a point line ("2.1 0 -1.2 ...") by its second field, a name.
      first = false;
      bool ok = t.size() >= 2 && parse_number(t[0], &v) && !parse_number(t[1], &v);
      for (size_t k = 2; ok && k < t.size(); ++k) ok = parse_number(t[k], &v);
      if (!ok)
        return error_at(source, l.number, "expected the visage header '<version> <name> <numbers>' or a "
                                          "feature point line 'G.I X Y Z [MESH.VERTEX]'");
      continue;
    }
    first = false;
    if (!point) {
      // "NUL n" / "NLL n": lip-region vertex counts; only empty lists are understood.
      int n = 0;
      if (t.size() == 2 && (t[0] == "NUL" || t[0] == "NLL") && parse_index(t[1], &n)) {
        if (n != 0)
          return error_at(source, l.number, std::string(t[0]) + " " + std::string(t[1]) +
                                                ": non-empty lip vertex lists are not supported (their "
                                                "layout is undocumented)");
        continue;
      }
      if (t[0].find('.') != std::string_view::npos && (t.size() == 4 || t.size() == 5))
        return error_at(source, l.number, unknown_fdp(t[0]));
      return error_at(source, l.number, "expected a feature point line 'G.I X Y Z [MESH.VERTEX]', found " +
                                            quoted(t[0]));
    }
    if (g >= 12 && g <= 17) continue;  // visage|SDK's own points, not MPEG-4
    std::optional<FdpId> id = FdpId::parse(t[0]);
    if (!id) return error_at(source, l.number, unknown_fdp(t[0]));
    FdpPoint p;
    p.id = *id;
    p.line = l.number;
    if (t.size() != 4 && t.size() != 5)
      return Status::error(fdp_location(set, p) + ": expected 'G.I X Y Z [MESH.VERTEX]', found " +
                           std::to_string(t.size()) + " fields");
    for (int k = 0; k < 3; ++k)
      if (!parse_number(t[k + 1], &p.pos[k]))
        return Status::error(fdp_location(set, p) + ": coordinate " + "xyz"[k] + " " + quoted(t[k + 1]) +
                             " is not a number");
    if (t.size() == 5) {
      // MESH.VERTEX is two integers, not a decimal: "0.10" is vertex 10 of mesh 0.
      std::string_view mv = t[4];
      size_t dot = mv.find('.');
      int mesh = 0;
      if (dot == std::string_view::npos || !parse_index(mv.substr(0, dot), &mesh) ||
          !parse_index(mv.substr(dot + 1), &p.vertex))
        return Status::error(fdp_location(set, p) + ": " + quoted(mv) +
                             " is not MESH.VERTEX (two non-negative integers)");
      p.part_name = "@" + std::to_string(mesh);
    }
    auto [it, inserted] = first_line.emplace(p.id, p.line);
    if (!inserted)
      return Status::error(fdp_location(set, p) + ": given twice (first at line " + std::to_string(it->second) + ")");
    set.points.push_back(std::move(p));
  }
  if (set.points.empty()) return no_points(source);
  return set;
}

FdpFormat detect(std::string_view text) {
  size_t i = text.substr(0, 3) == "\xEF\xBB\xBF" ? 3 : 0;
  while (i < text.size() && (text[i] == ' ' || text[i] == '\t' || text[i] == '\r' || text[i] == '\n')) ++i;
  if (i < text.size() && text[i] == '<') return FdpFormat::XfaceEd;
  std::vector<TextLine> lines = tokenize(text);
  if (lines.empty()) return FdpFormat::Text;
  const auto &t = lines[0].tokens;
  if (t[0] == "fapu" || t.size() == 3 || t.size() == 4) return FdpFormat::Text;
  return FdpFormat::Visage;
}

// Shortest text that reads back as the same double.
std::string number_text(double v) {
  char buf[64];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

bool writable_name(const std::string &s) {
  if (s.empty() || s[0] == '#' || s == "fapu") return false;
  for (char c : s)
    if (c == ' ' || c == '\t' || c == '\r' || c == '\n') return false;
  return true;
}

}  // namespace

Expected<FdpSet> parse_fdp(std::string_view text, const std::string &source_name, FdpFormat format) {
  if (format == FdpFormat::Auto) format = detect(text);
  switch (format) {
    case FdpFormat::XfaceEd: return parse_xfaceed(text, source_name);
    case FdpFormat::Visage: return parse_visage(text, source_name);
    case FdpFormat::Text:
    case FdpFormat::Auto: break;
  }
  return parse_text_form(text, source_name);
}

Expected<FdpSet> read_fdp(const std::string &path, FdpFormat format) {
  Expected<std::string> text = read_file(path);
  if (!text) return text.status();
  return parse_fdp(*text, path, format);
}

Status write_fdp_text(const FdpSet &fdps, const Scene &scene, const std::string &path, const Fapu *fapu) {
  std::string out = "# MPEG-4 feature points, text form (formats/fdp.md)\n";
  if (!fdps.source.empty()) out += "# from " + fdps.source + "\n";
  if (!scene.source.empty() || !scene.name.empty())
    out += "# scene " + (scene.source.empty() ? scene.name : scene.source) + "\n";
  if (fapu) {
    const double v[5] = {fapu->es0, fapu->irisd0, fapu->ens0, fapu->mns0, fapu->mw0};
    out += "fapu";
    for (double x : v) {
      if (!(std::isfinite(x) && x > 0))
        return Status::error(path + ": FAPU value " + number_text(x) + " is not a positive number");
      out += " " + number_text(x);
    }
    out += "\n";
  }
  for (const FdpPoint &p : fdps.points) {
    std::string line = p.id.str();
    if (p.part >= 0 || !p.part_name.empty()) {
      std::string name = p.part_name;
      if (p.part >= 0) {
        if (static_cast<size_t>(p.part) >= scene.parts.size())
          return Status::error(path + ": " + fdp_location(fdps, p) + ": part index " + std::to_string(p.part) +
                               " not in the scene (" + std::to_string(scene.parts.size()) + " parts)");
        name = scene.parts[static_cast<size_t>(p.part)].name;
      }
      if (!writable_name(name))
        return Status::error(path + ": " + fdp_location(fdps, p) + ": part name " + quoted(name) +
                             " cannot be written in the text form (empty, blank inside, or '#')");
      if (p.vertex < 0)
        return Status::error(path + ": " + fdp_location(fdps, p) + ": no vertex index");
      line += " " + name + " " + std::to_string(p.vertex);
    } else {
      for (int k = 0; k < 3; ++k) {
        if (!std::isfinite(p.pos[k]))
          return Status::error(path + ": " + fdp_location(fdps, p) + ": position is not finite");
        line += " " + number_text(p.pos[k]);
      }
    }
    out += line + "\n";
  }
  return write_file_atomic(path, out);
}

}  // namespace afmb
