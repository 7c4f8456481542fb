#include "core/part_kind.h"

#include <algorithm>
#include <cctype>
#include <initializer_list>
#include <string>
#include <vector>

namespace afmb {

namespace {

bool is_lower(char c) { return c >= 'a' && c <= 'z'; }
bool is_upper(char c) { return c >= 'A' && c <= 'Z'; }
bool is_digit(char c) { return c >= '0' && c <= '9'; }
bool is_alnum(char c) { return is_lower(c) || is_upper(c) || is_digit(c); }

std::vector<std::string> split_words(std::string_view name) {
  std::vector<std::string> words;
  std::string cur;
  char prev = 0;
  for (char c : name) {
    bool boundary = !is_alnum(c) || (is_digit(c) != is_digit(prev) && is_alnum(prev)) ||
                    (is_upper(c) && is_lower(prev));
    if (boundary && !cur.empty()) {
      words.push_back(cur);
      cur.clear();
    }
    if (is_alnum(c)) cur += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    prev = c;
  }
  if (!cur.empty()) words.push_back(cur);
  return words;
}

bool has_any(const std::vector<std::string> &words, std::initializer_list<const char *> set) {
  for (const std::string &w : words)
    for (const char *s : set)
      if (w == s) return true;
  return false;
}

}  // namespace

PartKind guess_part_kind(std::string_view name) {
  const std::vector<std::string> w = split_words(name);
  if (has_any(w, {"eyelid", "eyelids", "lid", "lids", "eyelash", "eyelashes", "lash", "lashes",
                  "eyebrow", "eyebrows", "brow", "brows", "eyeblow", "eyeblows"}))
    return PartKind::Eyelid;
  if (has_any(w, {"eye", "eyes", "eyeball", "eyeballs", "pupil", "pupils", "iris", "cornea"})) {
    if (has_any(w, {"left", "l", "lt"})) return PartKind::EyeLeft;
    if (has_any(w, {"right", "r", "rt"})) return PartKind::EyeRight;
    return PartKind::Other;
  }
  if (has_any(w, {"teeth", "tooth", "dentures"})) {
    if (has_any(w, {"upper", "up", "top", "maxilla"})) return PartKind::TeethUpper;
    if (has_any(w, {"lower", "low", "bottom", "bot", "mandible", "jaw"})) return PartKind::TeethLower;
    return PartKind::Other;
  }
  if (has_any(w, {"tongue"})) return PartKind::Tongue;
  if (has_any(w, {"hair", "hairs"})) return PartKind::Hair;
  if (has_any(w, {"throat", "mouth", "cavity", "palate", "gum", "gums"})) return PartKind::Mouth;
  if (has_any(w, {"head", "face", "skin"})) return PartKind::Skin;
  return PartKind::Other;
}

PartKind guess_part_kind(const Part &part) {
  PartKind k = guess_part_kind(part.name);
  for (size_t i = 0; k == PartKind::Other && i < part.aliases.size(); ++i)
    k = guess_part_kind(part.aliases[i]);
  return k;
}

void guess_part_kinds(Scene &scene) {
  for (Part &p : scene.parts) p.kind = guess_part_kind(p);
}

PartKind fdp_part_kind(FdpId id) {
  if (id == FdpId{3, 5}) return PartKind::EyeLeft;
  if (id == FdpId{3, 6}) return PartKind::EyeRight;
  if (id.group == 6) return PartKind::Tongue;
  if (id == FdpId{9, 8} || id == FdpId{9, 10}) return PartKind::TeethUpper;
  if (id == FdpId{9, 9} || id == FdpId{9, 11}) return PartKind::TeethLower;
  return PartKind::Skin;
}

void assign_part_kinds(Scene &scene, const FdpSet &bound) {
  const int n = static_cast<int>(scene.parts.size());
  std::vector<int> face_fdps(n, 0);   // FDPs of groups 2, 4, 5, 8, 9 per part
  std::vector<bool> has_chin(n, false), has_l(n, false), has_r(n, false), has_tongue(n, false);
  for (const FdpPoint &p : bound.points) {
    if (p.part < 0 || p.part >= n) continue;
    const int g = p.id.group;
    if (g == 2 || g == 4 || g == 5 || g == 8 || g == 9) ++face_fdps[p.part];
    if (p.id == FdpId{2, 1}) has_chin[p.part] = true;
    if (p.id == FdpId{3, 5}) has_l[p.part] = true;
    if (p.id == FdpId{3, 6}) has_r[p.part] = true;
    if (g == 6) has_tongue[p.part] = true;
  }
  int skin = -1;
  for (int i = 0; i < n; ++i)
    if (has_chin[i] && (skin < 0 || face_fdps[i] > face_fdps[skin])) skin = i;
  if (skin >= 0) {
    for (int i = 0; i < n; ++i)
      if (i != skin && scene.parts[i].kind == PartKind::Skin) scene.parts[i].kind = PartKind::Other;
    scene.parts[skin].kind = PartKind::Skin;
  }
  for (int i = 0; i < n; ++i) {
    if (i == skin) continue;
    if (has_l[i] && !has_r[i]) scene.parts[i].kind = PartKind::EyeLeft;
    else if (has_r[i] && !has_l[i]) scene.parts[i].kind = PartKind::EyeRight;
    else if (has_tongue[i]) scene.parts[i].kind = PartKind::Tongue;
  }
}

}  // namespace afmb
