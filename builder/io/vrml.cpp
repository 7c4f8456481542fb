#include "io/vrml.h"

#include <filesystem>
#include <Eigen/Geometry>
#include <charconv>
#include <cmath>
#include <map>
#include <memory>
#include <new>
#include <set>
#include <unordered_map>
#include <utility>
#include <vector>

#include "core/atomic_file.h"
#include "core/part_kind.h"

namespace afmb {

namespace {

// ---- errors ------------------------------------------------------------------
// Parsing unwinds with this private exception; parse_vrml() turns it into a
// Status, so nothing escapes the module.
struct VrmlError {
  std::string message;
};

// ---- tokens ------------------------------------------------------------------

enum class Tok : uint8_t { End, Word, Number, String, LBrace, RBrace, LBracket, RBracket };

struct Token {
  Tok kind = Tok::End;
  std::string_view text;  // the word, the number as written, or a string's raw contents
  double number = 0;
  int line = 0;
};

const char *describe(Tok k) {
  switch (k) {
    case Tok::End: return "end of file";
    case Tok::Word: return "a name";
    case Tok::Number: return "a number";
    case Tok::String: return "a string";
    case Tok::LBrace: return "'{'";
    case Tok::RBrace: return "'}'";
    case Tok::LBracket: return "'['";
    case Tok::RBracket: return "']'";
  }
  return "?";
}

std::string show(const Token &t) {
  switch (t.kind) {
    case Tok::Word:
    case Tok::Number: return "'" + std::string(t.text) + "'";
    case Tok::String: return "\"" + std::string(t.text.substr(0, 40)) + "\"";
    default: return describe(t.kind);
  }
}

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == ','; }
bool is_delim(char c) {
  return is_space(c) || c == '{' || c == '}' || c == '[' || c == ']' || c == '"' || c == '#';
}

// VRML97 lexical rules (ISO/IEC 14772-1 5.1): '#' comments to end of line,
// commas are whitespace, strings in double quotes with \" and \\ escapes.
class Lexer {
 public:
  Lexer(std::string_view text, const std::string &source) : s_(text), source_(source) {}

  const Token &peek() {
    if (!have_) {
      tok_ = scan();
      have_ = true;
    }
    return tok_;
  }
  Token next() {
    peek();
    have_ = false;
    return tok_;
  }

  [[noreturn]] void fail(int line, const std::string &msg) const {
    throw VrmlError{source_ + ":" + std::to_string(line) + ": " + msg};
  }
  const std::string &source() const { return source_; }

 private:
  Token scan() {
    for (;;) {
      while (pos_ < s_.size() && is_space(s_[pos_])) {
        if (s_[pos_] == '\n') ++line_;
        ++pos_;
      }
      if (pos_ < s_.size() && s_[pos_] == '#') {
        while (pos_ < s_.size() && s_[pos_] != '\n') ++pos_;
        continue;
      }
      break;
    }
    Token t;
    t.line = line_;
    if (pos_ >= s_.size()) return t;
    const char c = s_[pos_];
    switch (c) {
      case '{': t.kind = Tok::LBrace; ++pos_; return t;
      case '}': t.kind = Tok::RBrace; ++pos_; return t;
      case '[': t.kind = Tok::LBracket; ++pos_; return t;
      case ']': t.kind = Tok::RBracket; ++pos_; return t;
      case '"': return scan_string();
      default: break;
    }
    const size_t start = pos_;
    while (pos_ < s_.size() && !is_delim(s_[pos_])) ++pos_;
    t.text = s_.substr(start, pos_ - start);
    const bool numeric = (c >= '0' && c <= '9') || c == '.' ||
                         ((c == '+' || c == '-') && t.text.size() > 1 &&
                          ((t.text[1] >= '0' && t.text[1] <= '9') || t.text[1] == '.'));
    if (!numeric) {
      t.kind = Tok::Word;
      return t;
    }
    t.kind = Tok::Number;
    t.number = parse_number(t.text, t.line);
    return t;
  }

  Token scan_string() {
    Token t;
    t.kind = Tok::String;
    t.line = line_;
    const size_t start = ++pos_;
    while (pos_ < s_.size() && s_[pos_] != '"') {
      if (s_[pos_] == '\\' && pos_ + 1 < s_.size()) ++pos_;
      if (s_[pos_] == '\n') ++line_;
      ++pos_;
    }
    if (pos_ >= s_.size()) fail(t.line, "string opened here is never closed");
    t.text = s_.substr(start, pos_ - start);
    ++pos_;
    return t;
  }

  double parse_number(std::string_view text, int line) const {
    std::string_view body = text;
    bool negative = false;
    if (body[0] == '+' || body[0] == '-') {
      negative = body[0] == '-';
      body.remove_prefix(1);
    }
    double v = 0;
    const char *end = body.data() + body.size();
    if (body.size() > 2 && body[0] == '0' && (body[1] == 'x' || body[1] == 'X')) {
      // SFInt32 may be hexadecimal.
      long long h = 0;
      auto r = std::from_chars(body.data() + 2, end, h, 16);
      if (r.ec != std::errc() || r.ptr != end) fail(line, "malformed number '" + std::string(text) + "'");
      v = static_cast<double>(h);
    } else {
      auto r = std::from_chars(body.data(), end, v);
      if (r.ec != std::errc() || r.ptr != end) fail(line, "malformed number '" + std::string(text) + "'");
    }
    return negative ? -v : v;
  }

  std::string_view s_;
  const std::string &source_;
  size_t pos_ = 0;
  int line_ = 1;
  Token tok_;
  bool have_ = false;
};

std::string unescape(std::string_view raw) {
  std::string out;
  out.reserve(raw.size());
  for (size_t i = 0; i < raw.size(); ++i) {
    if (raw[i] == '\\' && i + 1 < raw.size()) ++i;
    out += raw[i];
  }
  return out;
}

// ---- node graph --------------------------------------------------------------

struct Node;
using NodePtr = std::shared_ptr<Node>;

// A field value as written, without a schema: numbers (with the line of
// each, for index errors), strings, a boolean, nodes.
struct Value {
  int line = 0;
  std::vector<double> nums;
  std::vector<int> num_lines;
  std::vector<std::string> strings;
  std::vector<NodePtr> nodes;
  int boolean = -1;  // -1 absent, 0 FALSE, 1 TRUE
};

struct Node {
  std::string type;
  std::string def;
  int line = 0;
  bool known = false;       // false: skipped whole, kept only so USE resolves
  int undef_ifs = -1;       // for an IndexedFaceSet without DEF: its 0-based rank among those
  std::vector<std::pair<std::string, Value>> fields;

  // A field given twice counts once, with its last value.
  const Value *field(std::string_view name) const {
    for (auto it = fields.rbegin(); it != fields.rend(); ++it)
      if (it->first == name) return &it->second;
    return nullptr;
  }
  NodePtr node(std::string_view name) const {
    const Value *v = field(name);
    return v && !v->nodes.empty() ? v->nodes[0] : nullptr;
  }
};

const std::set<std::string_view> &known_types() {
  static const std::set<std::string_view> k = {
      "Transform", "Group",      "Collision",         "Anchor",   "Billboard",
      "Switch",    "LOD",        "Shape",             "Appearance", "Material",
      "ImageTexture", "IndexedFaceSet", "Coordinate", "TextureCoordinate", "Color"};
  return k;
}

bool is_grouping(const std::string &t) {
  return t == "Transform" || t == "Group" || t == "Collision" || t == "Anchor" || t == "Billboard" ||
         t == "Switch" || t == "LOD";
}

class Parser {
 public:
  Parser(std::string_view text, const std::string &source) : lex_(text, source) {}

  std::vector<NodePtr> parse_file() {
    std::vector<NodePtr> roots;
    while (lex_.peek().kind != Tok::End) {
      const Token &t = lex_.peek();
      if (t.kind != Tok::Word) lex_.fail(t.line, "expected a node, found " + show(t));
      if (NodePtr n = statement()) roots.push_back(n);
    }
    return roots;
  }

 private:
  // One statement where nodes may appear: a node, PROTO, EXTERNPROTO or ROUTE.
  // Returns the node, or null for anything that is not a usable node.
  NodePtr statement() {
    const Token &t = lex_.peek();
    if (t.text == "PROTO") {
      skip_proto();
      return nullptr;
    }
    if (t.text == "EXTERNPROTO") {
      skip_externproto();
      return nullptr;
    }
    if (t.text == "ROUTE") {
      skip_route();
      return nullptr;
    }
    return node();
  }

  Token expect(Tok kind, const std::string &what) {
    Token t = lex_.next();
    if (t.kind != kind) lex_.fail(t.line, "expected " + what + ", found " + show(t));
    return t;
  }

  NodePtr node() {
    Token t = lex_.next();
    if (t.kind != Tok::Word) lex_.fail(t.line, "expected a node, found " + show(t));
    if (t.text == "NULL") return nullptr;
    if (t.text == "USE") {
      Token name = expect(Tok::Word, "a name after USE");
      auto it = defs_.find(std::string(name.text));
      if (it == defs_.end()) lex_.fail(name.line, "USE of undefined name '" + std::string(name.text) + "'");
      return it->second;
    }
    std::string def;
    if (t.text == "DEF") {
      def = std::string(expect(Tok::Word, "a name after DEF").text);
      t = expect(Tok::Word, "a node type after DEF " + def);
    }
    auto n = std::make_shared<Node>();
    n->type = std::string(t.text);
    n->def = def;
    n->line = t.line;
    const Token open = lex_.next();
    if (open.kind != Tok::LBrace)
      lex_.fail(open.line, "expected '{' after '" + n->type + "', found " + show(open));
    // Skipping an Inline would silently drop the geometry it brings.
    if (n->type == "Inline")
      lex_.fail(t.line, "Inline is not supported: put the inlined file's nodes in this file");
    n->known = known_types().count(n->type) != 0;
    if (n->known) {
      if (n->type == "IndexedFaceSet" && def.empty()) n->undef_ifs = undef_ifs_count_++;
      body(*n, open.line);
    } else {
      skip_block(open);
    }
    // Registered after the body: a node cannot USE itself (no cycles).
    if (!def.empty()) defs_[def] = n;
    return n;
  }

  void body(Node &n, int open_line) {
    for (;;) {
      const Token &t = lex_.peek();
      if (t.kind == Tok::RBrace) {
        lex_.next();
        return;
      }
      if (t.kind == Tok::End)
        lex_.fail(open_line, "'{' of " + n.type + " opened here is never closed");
      if (t.kind != Tok::Word)
        lex_.fail(t.line, "expected a field of " + n.type + " or '}', found " + show(t));
      if (t.text == "ROUTE") {
        skip_route();
        continue;
      }
      if (t.text == "PROTO") {
        skip_proto();
        continue;
      }
      Token name = lex_.next();
      Value v = value(name);
      n.fields.emplace_back(std::string(name.text), std::move(v));
    }
  }

  Value value(const Token &field) {
    Value v;
    const Token &t = lex_.peek();
    v.line = t.line;
    switch (t.kind) {
      case Tok::LBracket: {
        const Token open = lex_.next();
        for (;;) {
          const Token &e = lex_.peek();
          if (e.kind == Tok::RBracket) {
            lex_.next();
            break;
          }
          switch (e.kind) {
            case Tok::End:
              lex_.fail(open.line, "'[' of field '" + std::string(field.text) +
                                       "' opened here is never closed");
            case Tok::Number:
              v.nums.push_back(e.number);
              v.num_lines.push_back(e.line);
              lex_.next();
              break;
            case Tok::String:
              v.strings.push_back(unescape(e.text));
              lex_.next();
              break;
            case Tok::Word:
              if (e.text == "TRUE" || e.text == "FALSE") {
                v.boolean = e.text == "TRUE";
                lex_.next();
              } else if (NodePtr n = statement()) {
                v.nodes.push_back(n);
              }
              break;
            default:
              lex_.fail(e.line, "unexpected " + show(e) + " inside '[' of field '" +
                                    std::string(field.text) + "' opened at line " +
                                    std::to_string(open.line));
          }
        }
        break;
      }
      case Tok::Number:
        while (lex_.peek().kind == Tok::Number) {
          Token n = lex_.next();
          v.nums.push_back(n.number);
          v.num_lines.push_back(n.line);
        }
        break;
      case Tok::String:
        v.strings.push_back(unescape(lex_.next().text));
        break;
      case Tok::Word:
        if (t.text == "TRUE" || t.text == "FALSE") {
          v.boolean = t.text == "TRUE";
          lex_.next();
        } else if (t.text == "IS") {
          lex_.fail(t.line, "'IS' outside a PROTO body");
        } else if (NodePtr n = node()) {
          v.nodes.push_back(n);
        }
        break;
      default:
        lex_.fail(t.line, "expected a value for field '" + std::string(field.text) + "', found " +
                              show(t));
    }
    return v;
  }

  // Skips a '{...}' or '[...]' block whose opening token was just read,
  // checking that brackets pair up, and registers the DEFs inside so that
  // a later USE of them is not an error (such nodes are unknown: ignored).
  void skip_block(const Token &open) {
    std::vector<Token> stack{open};
    while (!stack.empty()) {
      Token t = lex_.next();
      switch (t.kind) {
        case Tok::End: {
          const Token &o = stack.back();
          lex_.fail(o.line, std::string(o.kind == Tok::LBrace ? "'{'" : "'['") +
                                " opened here is never closed");
        }
        case Tok::LBrace:
        case Tok::LBracket: stack.push_back(t); break;
        case Tok::RBrace:
        case Tok::RBracket: {
          const Tok want = t.kind == Tok::RBrace ? Tok::LBrace : Tok::LBracket;
          if (stack.back().kind != want)
            lex_.fail(t.line, "unexpected " + show(t) + ": " + describe(stack.back().kind) +
                                  " opened at line " + std::to_string(stack.back().line) +
                                  " is still open");
          stack.pop_back();
          break;
        }
        case Tok::Word:
          if (t.text == "DEF" && lex_.peek().kind == Tok::Word) {
            Token name = lex_.next();
            auto opaque = std::make_shared<Node>();
            opaque->def = std::string(name.text);
            opaque->line = name.line;
            if (lex_.peek().kind == Tok::Word) opaque->type = std::string(lex_.peek().text);
            defs_[opaque->def] = opaque;
          }
          break;
        default: break;
      }
    }
  }

  void skip_proto() {  // PROTO name [ interface ] { body }
    const Token kw = lex_.next();
    expect(Tok::Word, "a name after " + std::string(kw.text));
    skip_block(expect(Tok::LBracket, "'[' after the PROTO name"));
    skip_block(expect(Tok::LBrace, "'{' with the PROTO body"));
  }

  void skip_externproto() {  // EXTERNPROTO name [ interface ] url(s)
    lex_.next();
    expect(Tok::Word, "a name after EXTERNPROTO");
    skip_block(expect(Tok::LBracket, "'[' after the EXTERNPROTO name"));
    Token url = lex_.next();
    if (url.kind == Tok::LBracket) skip_block(url);
    else if (url.kind != Tok::String) lex_.fail(url.line, "expected the EXTERNPROTO url, found " + show(url));
  }

  void skip_route() {  // ROUTE a.b TO c.d
    lex_.next();
    expect(Tok::Word, "a node.event after ROUTE");
    Token to = expect(Tok::Word, "TO");
    if (to.text != "TO") lex_.fail(to.line, "expected TO in ROUTE, found " + show(to));
    expect(Tok::Word, "a node.event after TO");
  }

  Lexer lex_;
  std::unordered_map<std::string, NodePtr> defs_;
  int undef_ifs_count_ = 0;
};

// ---- scene building ------------------------------------------------------------

struct Builder {
  std::string source;     // for messages
  std::string file_name;  // for "<file>_<N>" aliases
  Scene scene;
  bool all_switch_choices = false;
  std::map<const Node *, int> ifs_count_memo;

  [[noreturn]] void fail(int line, const std::string &msg) const {
    throw VrmlError{source + ":" + std::to_string(line) + ": " + msg};
  }

  std::vector<NodePtr> children_of(const Node &n) const {
    if (n.type == "Switch") {
      const Value *w = n.field("whichChoice");
      const Value *c = n.field("choice");
      if (all_switch_choices) return c ? c->nodes : std::vector<NodePtr>{};
      int which = w && !w->nums.empty() ? static_cast<int>(w->nums[0]) : -1;
      if (!c || which < 0 || which >= static_cast<int>(c->nodes.size())) return {};
      return {c->nodes[which]};
    }
    if (n.type == "LOD") {  // the first level is the most detailed
      const Value *l = n.field("level");
      if (!l || l->nodes.empty()) return {};
      return {l->nodes[0]};
    }
    const Value *c = n.field("children");
    return c ? c->nodes : std::vector<NodePtr>{};
  }

  int ifs_count(const NodePtr &n) {
    if (!n || !n->known) return 0;
    auto it = ifs_count_memo.find(n.get());
    if (it != ifs_count_memo.end()) return it->second;
    int c = 0;
    if (n->type == "Shape") {
      NodePtr g = n->node("geometry");
      c = g && g->type == "IndexedFaceSet" ? 1 : 0;
    } else if (is_grouping(n->type)) {
      for (const NodePtr &k : children_of(*n)) c += ifs_count(k);
    }
    ifs_count_memo[n.get()] = c;
    return c;
  }

  static Eigen::Vector3d vec3(const Value *v, const Eigen::Vector3d &dflt) {
    if (!v || v->nums.size() < 3) return dflt;
    return {v->nums[0], v->nums[1], v->nums[2]};
  }
  static Eigen::AngleAxisd rot(const Value *v) {
    if (!v || v->nums.size() < 4) return Eigen::AngleAxisd::Identity();
    Eigen::Vector3d axis(v->nums[0], v->nums[1], v->nums[2]);
    if (axis.norm() == 0) return Eigen::AngleAxisd::Identity();
    return Eigen::AngleAxisd(v->nums[3], axis.normalized());
  }

  // VRML97 6.52: P' = T * C * R * SR * S * -SR * -C * P.
  Eigen::Affine3d local_transform(const Node &n) const {
    const Eigen::Vector3d t = vec3(n.field("translation"), Eigen::Vector3d::Zero());
    const Eigen::Vector3d c = vec3(n.field("center"), Eigen::Vector3d::Zero());
    const Eigen::Vector3d s = vec3(n.field("scale"), Eigen::Vector3d::Ones());
    const Eigen::AngleAxisd r = rot(n.field("rotation"));
    const Eigen::AngleAxisd sr = rot(n.field("scaleOrientation"));
    Eigen::Affine3d m = Eigen::Affine3d::Identity();
    m.translate(t).translate(c).rotate(r).rotate(sr).scale(s).rotate(sr.inverse()).translate(-c);
    return m;
  }

  void visit(const NodePtr &n, const Eigen::Affine3d &m, const std::string &hint) {
    if (!n || !n->known) return;
    if (is_grouping(n->type)) {
      Eigen::Affine3d mm = n->type == "Transform" ? m * local_transform(*n) : m;
      std::string h = hint;
      // The innermost DEF'd group holding exactly one mesh names it.
      if (!n->def.empty() && ifs_count(n) == 1) h = n->def;
      for (const NodePtr &k : children_of(*n)) visit(k, mm, h);
    } else if (n->type == "Shape") {
      NodePtr g = n->node("geometry");
      if (g && g->known && g->type == "IndexedFaceSet") add_part(*n, *g, m, hint);
    }
  }

  // Numbers of a field of a child node, e.g. Coordinate.point, checked to
  // come in tuples of `arity`.
  const Value *tuples(const NodePtr &node, const char *field, size_t arity) const {
    if (!node) return nullptr;
    const Value *v = node->field(field);
    if (v && v->nums.size() % arity != 0)
      fail(v->line, node->type + " " + field + " has " + std::to_string(v->nums.size()) +
                        " numbers, not a multiple of " + std::to_string(arity));
    return v;
  }

  // Splits an index field into polygons (empty ones dropped), checking each
  // index against `count`. `what` names the field in messages.
  std::vector<std::vector<int>> polygons(const Value *v, int count, const char *what,
                                         const char *unit, std::vector<int> *lines) const {
    std::vector<std::vector<int>> polys;
    if (!v) return polys;
    std::vector<int> cur;
    int first_line = 0;
    auto close = [&]() {
      if (cur.empty()) return;
      if (cur.size() < 3)
        fail(first_line, std::string("polygon of ") + std::to_string(cur.size()) + " in " + what +
                             " (a face needs at least 3 indices)");
      polys.push_back(std::move(cur));
      if (lines) lines->push_back(first_line);
      cur.clear();
    };
    for (size_t i = 0; i < v->nums.size(); ++i) {
      const double x = v->nums[i];
      const int line = v->num_lines[i];
      if (x != std::floor(x) || std::fabs(x) > 2e9)
        fail(line, std::string(what) + " value " + std::to_string(x) + " is not an integer");
      const int idx = static_cast<int>(x);
      if (idx == -1) {
        close();
        continue;
      }
      if (idx < 0 || idx >= count)
        fail(line, std::string(what) + " " + std::to_string(idx) + " out of range (" +
                       std::to_string(count) + " " + unit + ")");
      if (cur.empty()) first_line = line;
      cur.push_back(idx);
    }
    close();  // a missing final -1 is accepted
    return polys;
  }

  void add_part(const Node &shape, const Node &ifs, const Eigen::Affine3d &m,
                const std::string &hint) {
    Part part;
    NodePtr coord = ifs.node("coord");
    if (!coord || coord->type != "Coordinate")
      fail(ifs.line, "IndexedFaceSet has no Coordinate node in its coord field");
    const Value *pts = tuples(coord, "point", 3);
    const int np = pts ? static_cast<int>(pts->nums.size() / 3) : 0;
    part.V.resize(np, 3);
    for (int i = 0; i < np; ++i) {
      Eigen::Vector3d p(pts->nums[3 * i], pts->nums[3 * i + 1], pts->nums[3 * i + 2]);
      part.V.row(i) = (m * p).transpose();
    }

    const Value *ci = ifs.field("coordIndex");
    std::vector<int> poly_lines;
    const auto polys = polygons(ci, np, "coordIndex", "points", &poly_lines);

    // A mirroring transform turns counter-clockwise into clockwise.
    const Value *ccw = ifs.field("ccw");
    const bool flip = (ccw && ccw->boolean == 0) != (m.linear().determinant() < 0);

    auto fan = [flip](const std::vector<std::vector<int>> &ps, Eigen::MatrixXi &out) {
      int n = 0;
      for (const auto &p : ps) n += static_cast<int>(p.size()) - 2;
      out.resize(n, 3);
      int r = 0;
      for (const auto &p : ps)
        for (size_t k = 1; k + 1 < p.size(); ++k, ++r) {
          out(r, 0) = p[0];
          out(r, 1) = p[flip ? k + 1 : k];
          out(r, 2) = p[flip ? k : k + 1];
        }
    };
    fan(polys, part.F);

    NodePtr tc = ifs.node("texCoord");
    if (tc && tc->type == "TextureCoordinate") {
      const Value *tp = tuples(tc, "point", 2);
      const int nt = tp ? static_cast<int>(tp->nums.size() / 2) : 0;
      part.TC.resize(nt, 2);
      for (int i = 0; i < nt; ++i) part.TC.row(i) << tp->nums[2 * i], tp->nums[2 * i + 1];
      const Value *ti = ifs.field("texCoordIndex");
      std::vector<std::vector<int>> tpolys;
      if (ti && !ti->nums.empty()) {
        tpolys = polygons(ti, nt, "texCoordIndex", "texture coordinates", nullptr);
        if (tpolys.size() != polys.size())
          fail(ti->line, "texCoordIndex has " + std::to_string(tpolys.size()) +
                             " polygons, coordIndex has " + std::to_string(polys.size()));
        for (size_t i = 0; i < polys.size(); ++i)
          if (tpolys[i].size() != polys[i].size())
            fail(poly_lines[i], "polygon " + std::to_string(i) + " has " +
                                    std::to_string(polys[i].size()) + " indices in coordIndex but " +
                                    std::to_string(tpolys[i].size()) + " in texCoordIndex");
      } else {  // VRML97: without texCoordIndex, coordIndex indexes the texture coordinates
        tpolys = polygons(ci, nt, "coordIndex (used as texCoordIndex)", "texture coordinates",
                          nullptr);
      }
      fan(tpolys, part.FTC);
    } else {
      part.TC.resize(0, 2);
      part.FTC.resize(0, 3);
    }

    // Per-vertex colours, the simple cases only: colorPerVertex TRUE, with
    // colorIndex absent (colour i for point i) or per corner (a point takes
    // the colour of its first corner). Per-face colours are ignored.
    NodePtr col = ifs.node("color");
    const Value *cpv = ifs.field("colorPerVertex");
    part.C.resize(0, 3);
    if (col && col->type == "Color" && !(cpv && cpv->boolean == 0)) {
      const Value *cv = tuples(col, "color", 3);
      const int nc = cv ? static_cast<int>(cv->nums.size() / 3) : 0;
      auto colour = [&](int i) {
        return Eigen::RowVector3d(cv->nums[3 * i], cv->nums[3 * i + 1], cv->nums[3 * i + 2]);
      };
      const Value *cidx = ifs.field("colorIndex");
      if (cidx && !cidx->nums.empty()) {
        const auto cpolys = polygons(cidx, nc, "colorIndex", "colours", nullptr);
        if (cpolys.size() != polys.size())
          fail(cidx->line, "colorIndex has " + std::to_string(cpolys.size()) +
                               " polygons, coordIndex has " + std::to_string(polys.size()));
        part.C.setZero(np, 3);
        std::vector<bool> set(np, false);
        for (size_t i = 0; i < polys.size(); ++i) {
          if (cpolys[i].size() != polys[i].size())
            fail(poly_lines[i], "polygon " + std::to_string(i) +
                                    " has a different size in colorIndex and coordIndex");
          for (size_t k = 0; k < polys[i].size(); ++k)
            if (!set[polys[i][k]]) {
              part.C.row(polys[i][k]) = colour(cpolys[i][k]);
              set[polys[i][k]] = true;
            }
        }
      } else if (nc > 0) {
        if (nc < np)
          fail(col->line, "Color has " + std::to_string(nc) + " colours for " + std::to_string(np) +
                              " points");
        part.C.resize(np, 3);
        for (int i = 0; i < np; ++i) part.C.row(i) = colour(i);
      }
    }

    if (NodePtr app = shape.node("appearance"); app && app->type == "Appearance") {
      if (NodePtr mat = app->node("material"); mat && mat->type == "Material")
        part.diffuse = vec3(mat->field("diffuseColor"), part.diffuse);
      if (NodePtr tex = app->node("texture"); tex && tex->type == "ImageTexture")
        if (const Value *url = tex->field("url"); url && !url->strings.empty())
          part.texture = url->strings[0];
    }

    // Name: the innermost DEF'd group holding only this mesh, else the
    // IndexedFaceSet's DEF, else the Shape's, else "shape<N>".
    std::string name = hint;
    if (name.empty()) name = ifs.def;
    if (name.empty()) name = shape.def;
    if (name.empty()) name = "shape" + std::to_string(scene.parts.size());
    std::string unique = name;
    for (int k = 2; scene.find_part(unique) >= 0; ++k) unique = name + "_" + std::to_string(k);
    part.name = unique;
    if (!ifs.def.empty() && ifs.def != unique) part.aliases.push_back(ifs.def);
    if (!shape.def.empty() && shape.def != unique && shape.def != ifs.def)
      part.aliases.push_back(shape.def);
    if (ifs.undef_ifs >= 0) part.aliases.push_back(file_name + "_" + std::to_string(ifs.undef_ifs));
    part.kind = guess_part_kind(part);
    scene.parts.push_back(std::move(part));
  }
};

std::string base_name(const std::string &path) {
  return std::filesystem::path(path).filename().string();
}

std::string stem(const std::string &path) { return std::filesystem::path(path).stem().string(); }

// ---- writing -------------------------------------------------------------------

void put_number(std::string &out, double v) {
  char buf[32];
  auto r = std::to_chars(buf, buf + sizeof buf, v);  // shortest form that reads back exactly
  out.append(buf, r.ptr);
}

// The numbers of a row or vector, separated by blanks.
template <class Row>
void put_numbers(std::string &out, const Row &row) {
  for (Eigen::Index k = 0; k < row.size(); ++k) {
    if (k) out += ' ';
    put_number(out, row(k));
  }
}

// An MFVec field's values: one row of `M` a line, each ended by ','.
void put_rows(std::string &out, const Eigen::MatrixXd &M) {
  for (Eigen::Index i = 0; i < M.rows(); ++i) {
    out += "          ";
    put_numbers(out, M.row(i));
    out += ",\n";
  }
}

// An index field: one triangle of `F` a line, ended by -1.
void put_triangles(std::string &out, const Eigen::MatrixXi &F) {
  for (Eigen::Index i = 0; i < F.rows(); ++i)
    out += "          " + std::to_string(F(i, 0)) + ", " + std::to_string(F(i, 1)) + ", " +
           std::to_string(F(i, 2)) + ", -1,\n";
}

bool is_id_char(char c, bool first) {
  const unsigned char u = static_cast<unsigned char>(c);
  if (u <= 0x20 || c == '"' || c == '#' || c == '\'' || c == ',' || c == '.' || c == '[' ||
      c == '\\' || c == ']' || c == '{' || c == '}' || u == 0x7f)
    return false;
  if (first && ((c >= '0' && c <= '9') || c == '+' || c == '-')) return false;
  return true;
}

// A legal VRML97 identifier (ISO/IEC 14772-1 5.1.4 "Id"): illegal characters
// become '_'.
std::string vrml_id(const std::string &name) {
  std::string id = name.empty() ? std::string("part") : name;
  for (size_t i = 0; i < id.size(); ++i)
    if (!is_id_char(id[i], i == 0)) id[i] = '_';
  if (id == "DEF" || id == "USE" || id == "TRUE" || id == "FALSE" || id == "NULL" || id == "ROUTE" ||
      id == "PROTO" || id == "EXTERNPROTO" || id == "TO" || id == "IS")
    id = "_" + id;
  return id;
}

std::string quoted(const std::string &s) {
  std::string q = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') q += '\\';
    q += c;
  }
  return q + "\"";
}

}  // namespace

Expected<Scene> parse_vrml(std::string_view text, const std::string &source_name,
                           const VrmlReadOptions &options) {
  try {
    // A UTF-8 byte order mark before the header is tolerated.
    if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);
    if (text.substr(0, 10) == "#VRML V1.0")
      return Status::error(source_name + ":1: VRML 1.0 is not supported, only VRML97 (#VRML V2.0)");
    if (text.substr(0, 10) != "#VRML V2.0")
      return Status::error(source_name + ":1: not a VRML97 file: the first line must start with "
                                         "'#VRML V2.0'");
    Parser parser(text, source_name);
    std::vector<NodePtr> roots = parser.parse_file();
    Builder b;
    b.source = source_name;
    b.all_switch_choices = options.all_switch_choices;
    b.file_name = base_name(source_name);
    b.scene.name = stem(source_name);
    b.scene.source = source_name;
    for (const NodePtr &n : roots) b.visit(n, Eigen::Affine3d::Identity(), "");
    if (b.scene.parts.empty()) return Status::error(source_name + ": no IndexedFaceSet in the scene");
    return std::move(b.scene);
  } catch (const VrmlError &e) {
    return Status::error(e.message);
  } catch (const std::bad_alloc &) {
    return Status::error(source_name + ": out of memory");
  }
}

Expected<Scene> read_vrml(const std::string &path, const VrmlReadOptions &options) {
  Expected<std::string> text = read_file(path);
  if (!text) return text.status();
  Expected<Scene> s = parse_vrml(*text, path, options);
  if (s) s->source = path;
  return s;
}

Expected<std::string> vrml_parts_text(const Scene &scene, std::set<std::string> *used,
                                      const std::string &where) {
  std::string out;
  out.reserve(64 + scene.vertex_count() * 40 + scene.triangle_count() * 30);
  // DEF names must be unique in the file.
  auto unique_id = [used](const std::string &name) {
    std::string base = vrml_id(name), id = base;
    for (int k = 2; used->count(id); ++k) id = base + "_" + std::to_string(k);
    used->insert(id);
    return id;
  };
  for (const Part &p : scene.parts) {
    if (p.V.cols() != 3 || p.F.cols() != 3 || (p.FTC.rows() > 0 && p.FTC.rows() != p.F.rows()))
      return Status::error(where + ": part '" + p.name + "' has malformed matrices (V " +
                           std::to_string(p.V.rows()) + "x" + std::to_string(p.V.cols()) + ", F " +
                           std::to_string(p.F.rows()) + "x" + std::to_string(p.F.cols()) + ")");
    const std::string name = unique_id(p.name);
    std::string faces_name = p.name + "-FACES";
    for (const std::string &a : p.aliases)
      if (vrml_id(a) == a) {
        faces_name = a;
        break;
      }
    const std::string faces = unique_id(faces_name);
    out += "DEF " + name + " Transform {\n  children [\n    Shape {\n      appearance Appearance {\n";
    out += "        material Material { diffuseColor ";
    put_numbers(out, p.diffuse);
    out += " }\n";
    if (!p.texture.empty()) out += "        texture ImageTexture { url " + quoted(p.texture) + " }\n";
    out += "      }\n      geometry DEF " + faces + " IndexedFaceSet {\n";
    out += "        ccw TRUE\n        solid FALSE\n";
    out += "        coord Coordinate { point [\n";
    put_rows(out, p.V);
    out += "        ] }\n        coordIndex [\n";
    put_triangles(out, p.F);
    out += "        ]\n";
    if (p.TC.rows() > 0 && p.FTC.rows() == p.F.rows()) {
      out += "        texCoord TextureCoordinate { point [\n";
      put_rows(out, p.TC);
      out += "        ] }\n        texCoordIndex [\n";
      put_triangles(out, p.FTC);
      out += "        ]\n";
    }
    if (p.C.rows() == p.V.rows() && p.C.rows() > 0) {
      out += "        colorPerVertex TRUE\n        color Color { color [\n";
      put_rows(out, p.C);
      out += "        ] }\n";
    }
    out += "      }\n    }\n  ]\n}\n\n";
  }
  return out;
}

std::string vrml_string(const std::string &text) { return quoted(text); }

Status write_vrml(const Scene &scene, const std::string &path) {
  std::string out = "#VRML V2.0 utf8\n";
  if (!scene.name.empty()) out += "# " + scene.name + "\n";
  out += "\n";
  std::set<std::string> used;
  Expected<std::string> parts = vrml_parts_text(scene, &used, path);
  if (!parts) return parts.status();
  out += *parts;
  return write_file_atomic(path, out);
}

}  // namespace afmb
