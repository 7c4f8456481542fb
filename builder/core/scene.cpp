#include "core/scene.h"

namespace afmb {

namespace {
struct KindName {
  PartKind kind;
  const char *name;
};
constexpr KindName kKindNames[] = {
    {PartKind::Other, "other"},           {PartKind::Skin, "skin"},
    {PartKind::EyeLeft, "eye_left"},      {PartKind::EyeRight, "eye_right"},
    {PartKind::TeethUpper, "teeth_upper"}, {PartKind::TeethLower, "teeth_lower"},
    {PartKind::Tongue, "tongue"},         {PartKind::Hair, "hair"},
    {PartKind::Eyelid, "eyelid"},         {PartKind::Mouth, "mouth"},
};
}  // namespace

const char *part_kind_name(PartKind kind) {
  for (const KindName &k : kKindNames)
    if (k.kind == kind) return k.name;
  return "other";
}

bool part_kind_from_name(std::string_view name, PartKind *kind) {
  for (const KindName &k : kKindNames) {
    if (name == k.name) {
      *kind = k.kind;
      return true;
    }
  }
  return false;
}

bool Part::matches(std::string_view n) const {
  if (n == name) return true;
  for (const std::string &a : aliases)
    if (n == a) return true;
  return false;
}

int Scene::find_part(std::string_view n) const {
  for (size_t i = 0; i < parts.size(); ++i)
    if (parts[i].matches(n)) return static_cast<int>(i);
  return -1;
}

int Scene::find_kind(PartKind kind) const {
  for (size_t i = 0; i < parts.size(); ++i)
    if (parts[i].kind == kind) return static_cast<int>(i);
  return -1;
}

std::vector<int> Scene::find_kinds(std::initializer_list<PartKind> kinds) const {
  std::vector<int> out;
  for (PartKind k : kinds)
    for (size_t i = 0; i < parts.size(); ++i)
      if (parts[i].kind == k) out.push_back(static_cast<int>(i));
  return out;
}

size_t Scene::vertex_count() const {
  size_t n = 0;
  for (const Part &p : parts) n += static_cast<size_t>(p.V.rows());
  return n;
}

size_t Scene::triangle_count() const {
  size_t n = 0;
  for (const Part &p : parts) n += static_cast<size_t>(p.F.rows());
  return n;
}

}  // namespace afmb
