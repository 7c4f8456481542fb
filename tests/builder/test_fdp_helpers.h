// Helpers shared by the FDP and FAPU tests: small scenes, and the reference
// data read independently of the code under test.
#pragma once

#include <map>
#include <set>
#include <string>
#include <vector>

#include "core/scene.h"

namespace fdptest {

// A part called `name` (with `aliases`) holding `n` vertices; vertex i is at
// (i, 2i, 3i) so a bound position tells which vertex it came from.
afmb::Part numbered_part(const std::string &name, int n, std::vector<std::string> aliases = {});

// "2.2" -> ["18@song_head-FACES", "36@song_throat-FACES"], from a column of
// mpeg4-fdp-list.csv ("song_fdp_entries(index@submesh)" etc.).
std::map<std::string, std::multiset<std::string>> reference_entries(const std::string &column);

// The attribute `name` of the first <tag ...> in an XML text, found by plain
// string search (no XML parser): for reading stored values independently.
std::string first_attribute(const std::string &text, const std::string &tag, const std::string &name);

// Names in "DEF <name> IndexedFaceSet" of a VRML text, by plain string search.
std::set<std::string> vrml_face_set_names(const std::string &text);

// Vertex positions ("v x y z" lines) of an OBJ file; empty when unreadable.
std::vector<std::vector<double>> obj_vertices(const std::string &path);

}  // namespace fdptest
