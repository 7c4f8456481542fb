#include "test_fdp_helpers.h"

#include <cstdlib>
#include <fstream>
#include <sstream>

#include "../common/csv.h"
#include "../common/test_paths.h"

namespace fdptest {

afmb::Part numbered_part(const std::string &name, int n, std::vector<std::string> aliases) {
  afmb::Part p;
  p.name = name;
  p.aliases = std::move(aliases);
  p.V.resize(n, 3);
  for (int i = 0; i < n; ++i) p.V.row(i) << i, 2.0 * i, 3.0 * i;
  p.F.resize(0, 3);
  return p;
}

std::map<std::string, std::multiset<std::string>> reference_entries(const std::string &column) {
  std::map<std::string, std::multiset<std::string>> out;
  afmtest::CsvTable t = afmtest::read_csv(afmtest::shared_reference("mpeg4-fdp-list.csv"));
  for (auto &row : t.rows) {
    const std::string &cell = row[column];
    if (cell.empty()) continue;
    for (const std::string &e : afmtest::split(cell, ';')) out[row["fdp"]].insert(e);
  }
  return out;
}

std::string first_attribute(const std::string &text, const std::string &tag, const std::string &name) {
  size_t at = text.find("<" + tag + " ");
  if (at == std::string::npos) return {};
  size_t end = text.find('>', at);
  std::string element = text.substr(at, end - at);
  size_t a = element.find(" " + name + "=\"");
  if (a == std::string::npos) return {};
  a += name.size() + 3;
  return element.substr(a, element.find('"', a) - a);
}

std::set<std::string> vrml_face_set_names(const std::string &text) {
  std::set<std::string> names;
  size_t at = 0;
  while ((at = text.find("DEF ", at)) != std::string::npos) {
    at += 4;
    std::istringstream in(text.substr(at, 200));
    std::string name, node;
    in >> name >> node;
    if (node == "IndexedFaceSet") names.insert(name);
  }
  return names;
}

std::vector<std::vector<double>> obj_vertices(const std::string &path) {
  std::vector<std::vector<double>> v;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("v ", 0) != 0) continue;
    std::istringstream ls(line.substr(2));
    double x, y, z;
    if (ls >> x >> y >> z) v.push_back({x, y, z});
  }
  return v;
}

}  // namespace fdptest
