// Part kinds: the name rules and the FDP correction.
#include <gtest/gtest.h>

#include <string>

#include "core/part_kind.h"

namespace {

using afmb::PartKind;

TEST(PartKind, GuessedFromNames) {
  struct Case {
    const char *name;
    PartKind kind;
  } cases[] = {
      {"song_head", PartKind::Skin},
      {"song_head-FACES", PartKind::Skin},
      {"FaceMesh", PartKind::Skin},
      {"skin", PartKind::Skin},
      {"song_eyeball_left", PartKind::EyeLeft},
      {"LeftEye", PartKind::EyeLeft},
      {"eye_l", PartKind::EyeLeft},
      {"EyeR", PartKind::EyeRight},
      {"pupil_right", PartKind::EyeRight},
      {"eyes", PartKind::Other},  // which one is for the FDPs to say
      {"song_eyeblow_upper", PartKind::Eyelid},
      {"upper_lid_left", PartKind::Eyelid},  // a lid, not an eye
      {"Eyelashes", PartKind::Eyelid},
      {"brows", PartKind::Eyelid},
      {"song_teeth_upper", PartKind::TeethUpper},
      {"teethUpper", PartKind::TeethUpper},
      {"lower_teeth", PartKind::TeethLower},
      {"teeth", PartKind::Other},
      {"song_tongue", PartKind::Tongue},
      {"song_hair3", PartKind::Hair},
      {"song_throat", PartKind::Mouth},
      {"mouth_cavity", PartKind::Mouth},
      {"chair", PartKind::Other},  // words, not substrings
      {"headphones", PartKind::Other},
      {"Mesh01", PartKind::Other},
      {"", PartKind::Other},
  };
  for (const Case &c : cases)
    EXPECT_EQ(afmb::guess_part_kind(std::string(c.name)), c.kind) << c.name;
}

TEST(PartKind, NameDecidesBeforeAliases) {
  afmb::Part p;
  p.name = "mesh3";
  p.aliases = {"model.wrl_3", "tongue_geo"};
  EXPECT_EQ(afmb::guess_part_kind(p), PartKind::Tongue);
  p.name = "hair";
  EXPECT_EQ(afmb::guess_part_kind(p), PartKind::Hair);
}

afmb::FdpPoint on(int part, int group, int index) {
  afmb::FdpPoint p;
  p.id = {group, index};
  p.part = part;
  p.part_name = "p" + std::to_string(part);
  p.vertex = 0;
  return p;
}

TEST(PartKind, FdpsCorrectTheGuess) {
  afmb::Scene s;
  for (const char *n : {"face", "mesh1", "jaw_teeth_lower", "ball_a", "ball_b", "mesh5"}) {
    afmb::Part p;
    p.name = n;
    s.parts.push_back(p);
  }
  afmb::guess_part_kinds(s);
  EXPECT_EQ(s.parts[0].kind, PartKind::Skin);
  EXPECT_EQ(s.parts[1].kind, PartKind::Other);
  afmb::FdpSet f;
  // 2.1 on the skin (mesh1, many face FDPs) and on the lower teeth, as in Song.
  f.points = {on(1, 2, 1), on(1, 2, 2), on(1, 8, 3), on(1, 9, 3), on(2, 2, 1),
              on(3, 3, 5), on(4, 3, 6), on(5, 6, 1), on(-1, 3, 1)};
  afmb::assign_part_kinds(s, f);
  EXPECT_EQ(s.parts[0].kind, PartKind::Other);  // the name's guess, overruled
  EXPECT_EQ(s.parts[1].kind, PartKind::Skin);
  EXPECT_EQ(s.parts[2].kind, PartKind::TeethLower);
  EXPECT_EQ(s.parts[3].kind, PartKind::EyeLeft);
  EXPECT_EQ(s.parts[4].kind, PartKind::EyeRight);
  EXPECT_EQ(s.parts[5].kind, PartKind::Tongue);
}

}  // namespace
