// The MPEG-4 tables in formats/src/mpeg4_tables.c against the reference CSV
// files and notes in ../shared/reference, which the tests read at run time.
#include <afm/mpeg4.h>

#include <gtest/gtest.h>

#include <map>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "../common/csv.h"
#include "../common/test_paths.h"

namespace {

using afmtest::CsvTable;

// "2.10" -> {2, 10}, parsed here without the code under test; {-1, -1} when
// the text is not two dot-separated decimal numbers.
std::pair<int, int> split_fdp(const std::string &text) {
  size_t dot = text.find('.');
  if (dot == std::string::npos || dot == 0 || dot + 1 >= text.size()) return {-1, -1};
  for (size_t i = 0; i < text.size(); ++i)
    if (i != dot && (text[i] < '0' || text[i] > '9')) return {-1, -1};
  return {std::stoi(text.substr(0, dot)), std::stoi(text.substr(dot + 1))};
}

// The table's words as unit vectors in the MPEG-4 frame (+x the face's own
// left, +y up, +z forward), written out here independently of the C table.
bool word_vector(const std::string &word, int v[3]) {
  struct W {
    const char *word;
    int x, y, z;
  };
  static const W kWords[] = {
      {"left", 1, 0, 0}, {"right", -1, 0, 0}, {"up", 0, 1, 0},
      {"down", 0, -1, 0}, {"forward", 0, 0, 1},
  };
  for (const W &w : kWords) {
    if (word == w.word) {
      v[0] = w.x;
      v[1] = w.y;
      v[2] = w.z;
      return true;
    }
  }
  return false;
}

CsvTable load(const char *name) {
  CsvTable t = afmtest::read_csv(afmtest::shared_reference(name));
  EXPECT_EQ(t.error, "");
  return t;
}

TEST(Mpeg4Tables, EveryFapFieldMatchesTheReferenceTable) {
  AFM_REQUIRE_SHARED_REFERENCE();
  CsvTable t = load("mpeg4-fap-table.csv");
  ASSERT_EQ(t.rows.size(), static_cast<size_t>(AFM_FAP_COUNT));
  for (size_t r = 0; r < t.rows.size(); ++r) {
    auto &row = t.rows[r];
    SCOPED_TRACE("mpeg4-fap-table.csv row for FAP " + row["fap"]);
    int number = std::stoi(row["fap"]);
    ASSERT_EQ(number, static_cast<int>(r) + 1);
    const afm_fap_info *f = afm_fap(number);
    ASSERT_NE(f, nullptr);
    EXPECT_EQ(f->number, number);
    EXPECT_STREQ(f->name, row["name"].c_str());
    EXPECT_EQ(afm_fap_by_name(row["name"].c_str()), f);
    EXPECT_STREQ(afm_fapu_name(f->unit), row["fapu"].c_str());
    EXPECT_STREQ(f->positive, row["positive_motion"].c_str());
    EXPECT_EQ(f->group, std::stoi(row["group"]));
    EXPECT_EQ(f->quant_step, std::stoi(row["quant_step"]));

    const std::string &ub = row["uni_bi"];
    if (ub == "na") {
      EXPECT_EQ(f->motion, AFM_MOTION_HIGH_LEVEL);
      EXPECT_EQ(f->bidirectional, 0);
      EXPECT_EQ(f->unit, AFM_FAPU_NONE);
    } else {
      ASSERT_TRUE(ub == "B" || ub == "U") << ub;
      EXPECT_EQ(f->bidirectional, ub == "B" ? 1 : 0);
      EXPECT_NE(f->motion, AFM_MOTION_HIGH_LEVEL);
    }

    // FDP: "na", "2.1" or a list "6.3,6.4" of which the table keeps the first.
    const std::string &fdp = row["fdp"];
    const std::string &sub = row["fdp_subgroup"];
    if (fdp == "na") {
      EXPECT_EQ(sub, "na");
      EXPECT_EQ(f->fdp_group, 0);
      EXPECT_EQ(f->fdp_index, 0);
    } else {
      std::vector<std::string> fdps = afmtest::split(fdp, ',');
      std::vector<std::string> subs = afmtest::split(sub, ',');
      ASSERT_EQ(fdps.size(), subs.size());
      auto first = split_fdp(fdps[0]);
      EXPECT_EQ(f->fdp_group, first.first);
      EXPECT_EQ(f->fdp_index, first.second);
      EXPECT_EQ(f->fdp_index, std::stoi(subs[0]));
      for (const std::string &each : fdps) {
        auto gi = split_fdp(each);
        EXPECT_NE(afm_fdp_find(gi.first, gi.second), nullptr) << each;
      }
    }

    // Motion kind and direction from the table's words.
    const std::string &word = f->positive;
    int v[3];
    bool rotation = row["fapu"] == "AU" && word != "concave upward";
    if (word == "growing") {
      EXPECT_EQ(f->motion, AFM_MOTION_DILATE);
    } else if (word == "concave upward") {
      EXPECT_EQ(f->motion, AFM_MOTION_ROLL);
    } else if (ub != "na") {
      ASSERT_TRUE(word_vector(word, v)) << word;
      if (rotation) {
        EXPECT_EQ(f->motion, AFM_MOTION_ROTATE);
      } else {
        EXPECT_EQ(f->motion, AFM_MOTION_TRANSLATE);
        EXPECT_EQ(f->direction[0], v[0]);
        EXPECT_EQ(f->direction[1], v[1]);
        EXPECT_EQ(f->direction[2], v[2]);
      }
    }
  }
  EXPECT_EQ(afm_fap(0), nullptr);
  EXPECT_EQ(afm_fap(-1), nullptr);
  EXPECT_EQ(afm_fap(AFM_FAP_COUNT + 1), nullptr);
  EXPECT_EQ(afm_fap_by_name("open_mouth"), nullptr);
  EXPECT_EQ(afm_fap_by_name(""), nullptr);
  EXPECT_EQ(afm_fap_by_name(nullptr), nullptr);
}

TEST(Mpeg4Tables, DirectionsAreUnitVectorsOrZero) {
  for (int n = 1; n <= AFM_FAP_COUNT; ++n) {
    const afm_fap_info *f = afm_fap(n);
    ASSERT_NE(f, nullptr);
    int sq = f->direction[0] * f->direction[0] + f->direction[1] * f->direction[1] +
             f->direction[2] * f->direction[2];
    if (f->motion == AFM_MOTION_TRANSLATE || f->motion == AFM_MOTION_ROTATE)
      EXPECT_EQ(sq, 1) << "FAP " << n << " " << f->name;
    else
      EXPECT_EQ(sq, 0) << "FAP " << n << " " << f->name;
  }
}

// A small positive rotation about `direction` must move the gaze (+z) toward
// the table's word, or for a roll the top of the head (+y). Velocity of a
// point p under rotation about axis a is a x p.
TEST(Mpeg4Tables, RotationAxesProduceThePositiveMotion) {
  int rotations = 0;
  for (int n = 1; n <= AFM_FAP_COUNT; ++n) {
    const afm_fap_info *f = afm_fap(n);
    if (f->motion != AFM_MOTION_ROTATE) continue;
    ++rotations;
    bool roll = std::strstr(f->name, "roll") != nullptr;
    const int p[3] = {0, roll ? 1 : 0, roll ? 0 : 1};
    const int8_t *a = f->direction;
    int vel[3] = {a[1] * p[2] - a[2] * p[1], a[2] * p[0] - a[0] * p[2], a[0] * p[1] - a[1] * p[0]};
    int want[3];
    ASSERT_TRUE(word_vector(f->positive, want)) << f->name;
    EXPECT_EQ(vel[0], want[0]) << f->name;
    EXPECT_EQ(vel[1], want[1]) << f->name;
    EXPECT_EQ(vel[2], want[2]) << f->name;
  }
  EXPECT_EQ(rotations, 7);  // 4 eyeball yaw/pitch + 3 head rotations
  // The axes the brief spells out, checked directly too.
  EXPECT_EQ(afm_fap_by_name("head_yaw")->direction[1], 1);
  EXPECT_EQ(afm_fap_by_name("head_pitch")->direction[0], 1);
  EXPECT_EQ(afm_fap_by_name("head_roll")->direction[2], 1);
}

// Where our descriptions deliberately differ from mpeg4-fdp-list.csv, with the
// CSV's wording (formats/src/mpeg4_tables.c says why: the CSV mirrors these).
const std::map<std::string, std::string> kCsvMirrored = {
    {"2.6", "Midpoint between FFP 2.2 and 2.5 on the inner upper lip contour"},
    {"2.7", "Midpoint between FFP 2.2 and 2.4 on the inner upper lip contour"},
    {"2.8", "Midpoint between FFP 2.3 and 2.5 on the inner lower lip contour"},
    {"2.9", "Midpoint between FFP 2.3 and 2.4 on the inner lower lip contour"},
    {"8.5", "Midpoint between FFP 8.4 and 8.1 on outer upper lip contour"},
    {"8.6", "Midpoint between FFP 8.3 and 8.1 on outer upper lip contour"},
    {"8.7", "Midpoint between FFP 8.4 and 8.2 on outer lower lip contour"},
    {"8.8", "Midpoint between FFP 8.3 and 8.2 on outer lower lip contour"},
    {"10.7", "Lower contact point between right ear and face"},
    {"10.8", "Inner contact point between left ear and face"},
};

TEST(Mpeg4Tables, EveryFdpMatchesTheReferenceList) {
  AFM_REQUIRE_SHARED_REFERENCE();
  CsvTable t = load("mpeg4-fdp-list.csv");
  ASSERT_EQ(t.rows.size(), static_cast<size_t>(AFM_FDP_COUNT));
  const afm_fdp_info *table = afm_fdp_table();
  ASSERT_NE(table, nullptr);
  for (size_t r = 0; r < t.rows.size(); ++r) {
    auto &row = t.rows[r];
    SCOPED_TRACE("mpeg4-fdp-list.csv row for FDP " + row["fdp"]);
    auto gi = split_fdp(row["fdp"]);
    EXPECT_EQ(gi.first, std::stoi(row["group"]));
    EXPECT_EQ(table[r].group, gi.first);
    EXPECT_EQ(table[r].index, gi.second);
    auto mirrored = kCsvMirrored.find(row["fdp"]);
    if (mirrored == kCsvMirrored.end()) {
      EXPECT_STREQ(table[r].description, row["description"].c_str());
    } else {
      // The CSV still says what we corrected, and ours names the other side.
      EXPECT_EQ(row["description"], mirrored->second);
      EXPECT_STRNE(table[r].description, row["description"].c_str());
    }
    EXPECT_EQ(afm_fdp_find(gi.first, gi.second), &table[r]);
    int g = 0, i = 0;
    const std::string &name = row["fdp"];
    EXPECT_EQ(afm_fdp_parse(name.data(), name.size(), &g, &i), 1);
    EXPECT_EQ(g, gi.first);
    EXPECT_EQ(i, gi.second);
  }
}

TEST(Mpeg4Tables, FdpFindRejectsUndefinedPoints) {
  EXPECT_EQ(afm_fdp_find(1, 1), nullptr);
  EXPECT_EQ(afm_fdp_find(2, 0), nullptr);
  EXPECT_EQ(afm_fdp_find(2, 15), nullptr);
  EXPECT_EQ(afm_fdp_find(7, 2), nullptr);
  EXPECT_EQ(afm_fdp_find(9, 16), nullptr);
  EXPECT_EQ(afm_fdp_find(11, 7), nullptr);
  EXPECT_EQ(afm_fdp_find(12, 1), nullptr);
  EXPECT_EQ(afm_fdp_find(-3, 1), nullptr);
  ASSERT_NE(afm_fdp_find(11, 6), nullptr);
  EXPECT_STREQ(afm_fdp_find(11, 6)->description, "Back of skull");
}

TEST(Mpeg4Tables, FdpParseRejectsWhatIsNotAName) {
  const char *bad[] = {"2.0", "2.15", "12.1", "2.1x", "", " 2.1", "2.1 ", "+2.1",
                       "-2.1", "2.01", "02.1", "2.", ".1", "2..1", "2,1", "1.1",
                       "7.2", "2", "x", "2.100", "100.1"};
  for (const char *b : bad) {
    int g = 77, i = 88;
    EXPECT_EQ(afm_fdp_parse(b, std::strlen(b), &g, &i), 0) << "'" << b << "'";
    EXPECT_EQ(g, 77) << b;
    EXPECT_EQ(i, 88) << b;
  }
  EXPECT_EQ(afm_fdp_parse(nullptr, 0, nullptr, nullptr), 0);
  // The length bounds the text: "2.10" cut to 3 characters is "2.1".
  int g = 0, i = 0;
  EXPECT_EQ(afm_fdp_parse("2.10", 3, &g, &i), 1);
  EXPECT_EQ(g, 2);
  EXPECT_EQ(i, 1);
  EXPECT_EQ(afm_fdp_parse("2.10", 4, &g, &i), 1);
  EXPECT_EQ(i, 10);
  EXPECT_EQ(afm_fdp_parse("11.6", 4, nullptr, nullptr), 1);
}

TEST(Mpeg4Tables, EveryTableFdpNameParsesBack) {
  const afm_fdp_info *table = afm_fdp_table();
  for (int k = 0; k < AFM_FDP_COUNT; ++k) {
    std::string name = std::to_string(table[k].group) + "." + std::to_string(table[k].index);
    int g = 0, i = 0;
    EXPECT_EQ(afm_fdp_parse(name.data(), name.size(), &g, &i), 1) << name;
    EXPECT_EQ(g, table[k].group);
    EXPECT_EQ(i, table[k].index);
    if (k > 0) {  // table order: by group, then index
      bool ascending = table[k - 1].group < table[k].group ||
                       (table[k - 1].group == table[k].group && table[k - 1].index < table[k].index);
      EXPECT_TRUE(ascending) << name;
    }
  }
}

// The notes list visemes as "none, p/b/m, f/v, T/D (th), ..." and expressions
// as "neutral, joy, ...": split at commas outside parentheses.
std::vector<std::string> notes_list(const std::string &notes, const std::string &lead) {
  size_t at = notes.find(lead);
  if (at == std::string::npos) return {};
  at += lead.size();
  size_t end = notes.find('\n', at);
  std::string line = notes.substr(at, end == std::string::npos ? std::string::npos : end - at);
  std::vector<std::string> items;
  std::string cur;
  int depth = 0;
  for (char c : line) {
    if (c == '(') ++depth;
    if (c == ')') --depth;
    if (c == ',' && depth == 0) {
      items.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  items.push_back(cur);
  for (std::string &s : items) {
    size_t paren = s.find('(');
    if (paren != std::string::npos) s = s.substr(0, paren);
    while (!s.empty() && (s.back() == ' ' || s.back() == '.')) s.pop_back();
    while (!s.empty() && s.front() == ' ') s.erase(0, 1);
  }
  return items;
}

TEST(Mpeg4Tables, VisemesAndExpressionsMatchTheNotes) {
  AFM_REQUIRE_SHARED_REFERENCE();
  std::string notes = afmtest::read_file(afmtest::shared_reference("mpeg4-fap-fdp-notes.md"));
  ASSERT_FALSE(notes.empty());
  std::vector<std::string> visemes = notes_list(notes, "Viseme numbers 0..14:");
  ASSERT_EQ(visemes.size(), static_cast<size_t>(AFM_VISEME_COUNT));
  EXPECT_EQ(visemes[0], "none");
  EXPECT_STREQ(afm_viseme_name(0), "none");
  EXPECT_STREQ(afm_viseme_phonemes(0), "");
  for (int v = 1; v < AFM_VISEME_COUNT; ++v) {
    std::string want;  // "tS/dZ/S" -> "tS, dZ, S"
    for (char c : visemes[v]) want += c == '/' ? std::string(", ") : std::string(1, c);
    EXPECT_EQ(afm_viseme_phonemes(v), want) << "viseme " << v;
    std::string name = afm_viseme_name(v);
    EXPECT_FALSE(name.empty());
    EXPECT_EQ(name.find_first_of(" ,:/"), std::string::npos) << name;
  }
  EXPECT_EQ(afm_viseme_name(-1), nullptr);
  EXPECT_EQ(afm_viseme_name(AFM_VISEME_COUNT), nullptr);
  EXPECT_EQ(afm_viseme_phonemes(AFM_VISEME_COUNT), nullptr);

  std::vector<std::string> expressions = notes_list(notes, "Expression numbers 0..6:");
  ASSERT_EQ(expressions.size(), static_cast<size_t>(AFM_EXPRESSION_COUNT));
  for (int e = 0; e < AFM_EXPRESSION_COUNT; ++e)
    EXPECT_EQ(afm_expression_name(e), expressions[e]) << "expression " << e;
  EXPECT_EQ(afm_expression_name(-1), nullptr);
  EXPECT_EQ(afm_expression_name(AFM_EXPRESSION_COUNT), nullptr);
}

TEST(Mpeg4Tables, FapuNames) {
  EXPECT_STREQ(afm_fapu_name(AFM_FAPU_NONE), "na");
  EXPECT_STREQ(afm_fapu_name(AFM_FAPU_IRISD), "IRISD");
  EXPECT_STREQ(afm_fapu_name(AFM_FAPU_ES), "ES");
  EXPECT_STREQ(afm_fapu_name(AFM_FAPU_ENS), "ENS");
  EXPECT_STREQ(afm_fapu_name(AFM_FAPU_MNS), "MNS");
  EXPECT_STREQ(afm_fapu_name(AFM_FAPU_MW), "MW");
  EXPECT_STREQ(afm_fapu_name(AFM_FAPU_AU), "AU");
  EXPECT_STREQ(afm_fapu_name(static_cast<afm_fapu>(99)), "?");
}

}  // namespace
