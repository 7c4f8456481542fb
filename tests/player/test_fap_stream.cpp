// ASCII FAP stream reader (player_c/include/afm/fap_stream.h, formats/fap.md).
//
// References are independent of the reader: values read by hand off the real
// files in ../shared/data/fap (file and line given beside each), the frame
// count each header states, the LF and CRLF copies of joy.fap, and streams
// written here by hand.
#include <afm/fap_stream.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "../common/csv.h"
#include "../common/test_paths.h"

namespace fs = std::filesystem;

namespace {

struct Parsed {
  afm_result result = AFM_OK;
  std::vector<afm_fap_frame> frames;
  bool has_header = false;
  afm_fap_header header{};
  afm_fap_stats stats{};
  afm_diag diag{};
};

std::vector<uint8_t> bytes(const std::string &s) { return std::vector<uint8_t>(s.begin(), s.end()); }

// Whole buffer through afm_fap_parse: count first, then fill. The data sits
// in a buffer of exactly its size, so the sanitizer sees any over-read.
Parsed parse_whole(const std::string &text, uint32_t flags = 0) {
  Parsed p;
  std::vector<uint8_t> data = bytes(text);
  afm_fap_reader_options opt{};
  opt.flags = flags;
  uint32_t count = 0;
  afm_result r = afm_fap_parse(data.data(), data.size(), &opt, nullptr, 0, &count, &p.header,
                               &p.stats, &p.diag);
  if (r == AFM_OK) {
    p.frames.resize(count);
    p.diag = afm_diag{};
    uint32_t count2 = 0;
    r = afm_fap_parse(data.data(), data.size(), &opt, p.frames.data(), count, &count2,
                      &p.header, &p.stats, &p.diag);
    EXPECT_EQ(count2, count);
  } else {
    // Errors: keep the frames read before it, through the incremental path's
    // own count (frames[] stay valid).
    p.frames.resize(count);
    uint32_t count2 = 0;
    afm_diag d{};
    afm_fap_parse(data.data(), data.size(), &opt, p.frames.data(), count, &count2, nullptr,
                  nullptr, &d);
  }
  p.result = r;
  p.has_header = p.header.version_major != 0;
  return p;
}

// Incremental: chunks of sizes from `next_size`, each copied into a buffer
// of exactly its size.
template <class NextSize>
Parsed parse_chunks(const std::string &text, NextSize next_size, uint32_t flags = 0) {
  Parsed p;
  afm_fap_reader_options opt{};
  opt.flags = flags;
  auto reader = std::make_unique<afm_fap_reader>();
  afm_fap_reader_init(reader.get(), &opt, &p.diag);
  size_t at = 0;
  afm_result r = AFM_OK;
  afm_fap_frame frame;
  while (at < text.size() && r == AFM_OK) {
    size_t n = std::min(text.size() - at, next_size());
    std::vector<uint8_t> chunk(text.begin() + static_cast<std::ptrdiff_t>(at),
                               text.begin() + static_cast<std::ptrdiff_t>(at + n));
    size_t off = 0;
    while (r == AFM_OK) {
      size_t used = 0;
      int has = 0;
      r = afm_fap_reader_feed(reader.get(), chunk.data() + off, chunk.size() - off, &used,
                              &frame, &has);
      off += used;
      if (has) p.frames.push_back(frame);
      if (off == chunk.size() && !has) break;
      if (r == AFM_OK && !has && off < chunk.size()) {
        ADD_FAILURE() << "feed stopped without a frame or error";
        break;
      }
    }
    at += n;
  }
  while (r == AFM_OK) {
    int has = 0;
    r = afm_fap_reader_finish(reader.get(), &frame, &has);
    if (!has) break;
    p.frames.push_back(frame);
  }
  p.result = r;
  if (const afm_fap_header *h = afm_fap_reader_header(reader.get())) {
    p.has_header = true;
    p.header = *h;
  }
  p.stats = *afm_fap_reader_stats(reader.get());
  return p;
}

bool same_frame(const afm_fap_frame &a, const afm_fap_frame &b) {
  return a.number == b.number && a.line == b.line &&
         std::memcmp(a.mask, b.mask, sizeof a.mask) == 0 &&
         std::memcmp(a.value, b.value, sizeof a.value) == 0 &&
         a.viseme.select1 == b.viseme.select1 && a.viseme.select2 == b.viseme.select2 &&
         a.viseme.blend == b.viseme.blend && a.viseme.def == b.viseme.def &&
         a.expression.select1 == b.expression.select1 &&
         a.expression.intensity1 == b.expression.intensity1 &&
         a.expression.select2 == b.expression.select2 &&
         a.expression.intensity2 == b.expression.intensity2 &&
         a.expression.init_face == b.expression.init_face && a.expression.def == b.expression.def;
}

bool same_stats(const afm_fap_stats &a, const afm_fap_stats &b) {
  return a.frames == b.frames && a.clamped == b.clamped && a.rounded == b.rounded &&
         a.comment_lines == b.comment_lines && a.masks_69 == b.masks_69 &&
         a.single_visemes == b.single_visemes && a.skipped_values == b.skipped_values;
}

void expect_same(const Parsed &a, const Parsed &b, const std::string &what) {
  SCOPED_TRACE(what);
  EXPECT_EQ(a.result, b.result);
  EXPECT_STREQ(a.diag.message, b.diag.message);
  EXPECT_EQ(a.diag.line, b.diag.line);
  ASSERT_EQ(a.frames.size(), b.frames.size());
  for (size_t i = 0; i < a.frames.size(); ++i)
    ASSERT_TRUE(same_frame(a.frames[i], b.frames[i])) << "frame " << i;
  EXPECT_TRUE(same_stats(a.stats, b.stats));
  EXPECT_EQ(a.has_header, b.has_header);
  if (a.has_header && b.has_header) {
    EXPECT_STREQ(a.header.name, b.header.name);
    EXPECT_EQ(a.header.fps_num, b.header.fps_num);
    EXPECT_EQ(a.header.fps_den, b.header.fps_den);
    EXPECT_EQ(a.header.frame_count, b.header.frame_count);
  }
}

std::vector<std::string> real_fap_files() {
  std::vector<std::string> out;
  for (const auto &e : fs::recursive_directory_iterator(afmtest::shared_data("fap")))
    if (e.is_regular_file() && e.path().extension() == ".fap") out.push_back(e.path().string());
  std::sort(out.begin(), out.end());
  return out;
}

const afm_fap_frame *find_frame(const Parsed &p, uint32_t number) {
  for (const auto &f : p.frames)
    if (f.number == number) return &f;
  return nullptr;
}

// A 68-entry mask line with the given FAPs set.
std::string mask(std::initializer_list<int> faps, int entries = 68, const char *sep = " ") {
  std::vector<int> m(static_cast<size_t>(entries) + 1, 0);
  for (int f : faps) m[static_cast<size_t>(f)] = 1;
  std::string s;
  for (int i = 1; i <= entries; ++i) {
    if (i > 1) s += sep;
    s += m[static_cast<size_t>(i)] ? "1" : "0";
  }
  return s;
}

// ---- real files --------------------------------------------------------------

TEST(FapStreamReal, EveryFileParsesToItsHeaderFrameCount) {
  AFM_REQUIRE_SHARED_DATA();
  auto files = real_fap_files();
  // SOURCES.md lists 13 .fap files (10 xface, 3 crystal).
  ASSERT_GE(files.size(), 13u);
  for (const auto &path : files) {
    SCOPED_TRACE(path);
    Parsed p = parse_whole(afmtest::read_file(path));
    ASSERT_EQ(p.result, AFM_OK) << p.diag.message;
    ASSERT_TRUE(p.has_header);
    EXPECT_EQ(p.frames.size(), p.header.frame_count);
    EXPECT_EQ(p.stats.frames, p.header.frame_count);
    EXPECT_EQ(p.header.version_major, 2);
    EXPECT_EQ(p.header.version_minor, 1);
    EXPECT_EQ(p.header.fps_num, 25u);
    EXPECT_EQ(p.header.fps_den, 1u);
    // Every real file numbers its frames 0, 1, 2, ... (checked by eye on the
    // first and last lines of each).
    for (size_t i = 0; i < p.frames.size(); ++i) ASSERT_EQ(p.frames[i].number, i);
    EXPECT_EQ(p.stats.masks_69, 0u);
    EXPECT_EQ(p.stats.single_visemes, 0u);
  }
}

TEST(FapStreamReal, HeaderFrameCountsAsWritten) {
  AFM_REQUIRE_SHARED_DATA();
  // Line 1 of each file, read by hand.
  struct {
    const char *file;
    uint32_t count;
  } cases[] = {{"fap/xface/joy.fap", 108},       {"fap/xface/anger.fap", 108},
               {"fap/xface/beg.fap", 107},       {"fap/xface/test.fap", 43},
               {"fap/crystal/interpolation_emot.fap", 224},
               {"fap/crystal/basic_emotion.fap", 13},
               {"fap/crystal/7_basic_emotion.fap", 7}};
  for (const auto &c : cases) {
    SCOPED_TRACE(c.file);
    Parsed p = parse_whole(afmtest::read_file(afmtest::shared_data(c.file)));
    ASSERT_EQ(p.result, AFM_OK) << p.diag.message;
    EXPECT_EQ(p.header.frame_count, c.count);
    EXPECT_EQ(p.frames.size(), c.count);
  }
}

TEST(FapStreamReal, JoyValuesReadByHand) {
  AFM_REQUIRE_SHARED_DATA();
  Parsed p = parse_whole(afmtest::read_file(afmtest::shared_data("fap/xface/joy.fap")));
  ASSERT_EQ(p.result, AFM_OK) << p.diag.message;
  // joy.fap:1 "2.1 C:\Users\balci\Work\FACE\exml2fap\files\TempFile 25 108"
  EXPECT_STREQ(p.header.name, "C:\\Users\\balci\\Work\\FACE\\exml2fap\\files\\TempFile");
  EXPECT_EQ(p.header.frame_count, 108u);
  ASSERT_EQ(p.frames.size(), 108u);
  // joy.fap:2 mask "0 0 1 ... (FAPs 3-26, 39-42, 48-60, 63)"; :3 "0 0 10 10 0 0 10 ..."
  const afm_fap_frame &f0 = p.frames[0];
  EXPECT_EQ(f0.number, 0u);
  EXPECT_EQ(f0.line, 3u);
  EXPECT_EQ(f0.mask[1], 0);
  EXPECT_EQ(f0.mask[2], 0);
  EXPECT_EQ(f0.mask[3], 1);
  EXPECT_EQ(f0.mask[26], 1);
  EXPECT_EQ(f0.mask[27], 0);
  EXPECT_EQ(f0.mask[39], 1);
  EXPECT_EQ(f0.mask[63], 1);
  EXPECT_EQ(f0.mask[64], 0);
  EXPECT_EQ(f0.value[3], 0);
  EXPECT_EQ(f0.value[4], 10);
  EXPECT_EQ(f0.value[5], 10);
  EXPECT_EQ(f0.value[51], 10);  // 32nd value
  // joy.fap:161 "79 -6 -83 60 42 ... 0 0 94 94 1411 -2245 -3619 -40 ..."
  const afm_fap_frame *f79 = find_frame(p, 79);
  ASSERT_NE(f79, nullptr);
  EXPECT_EQ(f79->line, 161u);
  EXPECT_EQ(f79->value[3], 0);  // open_jaw -6: unidirectional, clamped to 0
  EXPECT_EQ(f79->value[4], -83);
  EXPECT_EQ(f79->value[5], 60);
  EXPECT_EQ(f79->value[41], 94);
  EXPECT_EQ(f79->value[48], 1411);
  EXPECT_EQ(f79->value[49], -2245);
  EXPECT_EQ(f79->value[50], -3619);
  EXPECT_EQ(f79->value[51], -40);
  // joy.fap:216-217, the last frame: "107 0 10 10 0 0 10 10 10 10 ..."
  EXPECT_EQ(p.frames.back().number, 107u);
  EXPECT_EQ(p.frames.back().line, 217u);
  EXPECT_EQ(p.frames.back().value[4], 10);
  EXPECT_EQ(p.stats.rounded, 0u);  // integers only
  // joy.fap:159 and :161 send open_jaw -5 and -6; no other value of joy.fap is
  // out of range (its largest is 3622 AU; the unidirectional 14, 41 and 42 it
  // sends are never negative: checked with awk on the value lines).
  EXPECT_EQ(p.stats.clamped, 2u);
  EXPECT_EQ(p.stats.comment_lines, 0u);
}

TEST(FapStreamReal, OtherXfaceValuesReadByHand) {
  AFM_REQUIRE_SHARED_DATA();
  {
    // test.fap:87 "42 80 -90 -103 69 69 ... 15 15 1764 -3816 -1684 -86 ..."
    Parsed p = parse_whole(afmtest::read_file(afmtest::shared_data("fap/xface/test.fap")));
    ASSERT_EQ(p.result, AFM_OK) << p.diag.message;
    const afm_fap_frame &f = p.frames.back();
    EXPECT_EQ(f.number, 42u);
    EXPECT_EQ(f.line, 87u);
    EXPECT_EQ(f.value[3], 80);
    EXPECT_EQ(f.value[4], -90);
    EXPECT_EQ(f.value[14], 8);
    EXPECT_EQ(f.value[41], 15);
    EXPECT_EQ(f.value[48], 1764);
    EXPECT_EQ(f.value[49], -3816);
    EXPECT_EQ(f.value[50], -1684);
    EXPECT_EQ(f.value[51], -86);
    EXPECT_EQ(f.mask[21], 0);
  }
  {
    // anger.fap:201 "99 1 -51 8 30 30 ... -61 -61 -541 -541 -285 -285 -42 ..."
    Parsed p = parse_whole(afmtest::read_file(afmtest::shared_data("fap/xface/anger.fap")));
    ASSERT_EQ(p.result, AFM_OK) << p.diag.message;
    const afm_fap_frame *f = find_frame(p, 99);
    ASSERT_NE(f, nullptr);
    EXPECT_EQ(f->line, 201u);
    EXPECT_EQ(f->value[3], 1);
    EXPECT_EQ(f->value[19], -61);
    EXPECT_EQ(f->value[23], -541);
    EXPECT_EQ(f->value[31], -42);
    EXPECT_EQ(f->value[48], -396);
  }
}

TEST(FapStreamReal, InterpolationEmotFloatsAndEmptyFirstFrame) {
  AFM_REQUIRE_SHARED_DATA();
  Parsed p = parse_whole(
      afmtest::read_file(afmtest::shared_data("fap/crystal/interpolation_emot.fap")));
  ASSERT_EQ(p.result, AFM_OK) << p.diag.message;
  ASSERT_EQ(p.frames.size(), 224u);
  EXPECT_STREQ(p.header.name, "Xface::FapFile");
  // :2 all 68 mask entries 0; :3 "0 " (the frame number only).
  const afm_fap_frame &f0 = p.frames[0];
  EXPECT_EQ(f0.number, 0u);
  EXPECT_EQ(f0.line, 3u);
  for (int f = 1; f <= AFM_FAP_COUNT; ++f) {
    EXPECT_EQ(f0.mask[f], 0) << f;
    EXPECT_EQ(f0.value[f], 0) << f;
  }
  // :5 "1 0.322581 -4.61945 0.322581 0.322581 -6.92916 ..." (mask :4: FAPs 4, 5, 8-11, 19, 20, 22, ...)
  const afm_fap_frame &f1 = p.frames[1];
  EXPECT_EQ(f1.line, 5u);
  EXPECT_EQ(f1.value[4], 0);    // 0.322581
  EXPECT_EQ(f1.value[5], -5);   // -4.61945, rounded away from zero
  EXPECT_EQ(f1.value[10], -7);  // -6.92916
  EXPECT_EQ(f1.value[20], -17); // -17.1011
  EXPECT_EQ(f1.value[35], 5);   // 5.18565
  // :105 frame 51: FAP 32 = -216.5, an exact half: away from zero.
  const afm_fap_frame *f51 = find_frame(p, 51);
  ASSERT_NE(f51, nullptr);
  EXPECT_EQ(f51->line, 105u);
  EXPECT_EQ(f51->value[32], -217);
  EXPECT_EQ(f51->value[31], -176);  // -176.312
  EXPECT_EQ(f51->value[39], -18);   // -17.8511 (puff_l_cheek: bidirectional)
  // :359 frame 178: FAP 24 = -58064.5 (AU, in range)
  const afm_fap_frame *f178 = find_frame(p, 178);
  ASSERT_NE(f178, nullptr);
  EXPECT_EQ(f178->value[24], -58065);
  EXPECT_EQ(f178->value[23], 314159);  // 348387 AU > pi: clamped
  // :385 frame 191: "191 10 -143.203 ... -706.844 600000 -100000 300000 -58.251 ..."
  const afm_fap_frame *f191 = find_frame(p, 191);
  ASSERT_NE(f191, nullptr);
  EXPECT_EQ(f191->line, 385u);
  EXPECT_EQ(f191->value[5], -143);
  EXPECT_EQ(f191->value[20], -707);
  EXPECT_EQ(f191->value[23], 314159);  // yaw_l_eyeball 600000 AU (6 rad): clamped to pi
  EXPECT_EQ(f191->value[24], -100000);
  EXPECT_EQ(f191->value[25], 300000);
  EXPECT_EQ(f191->value[28], -58);
  EXPECT_GT(p.stats.rounded, 0u);
  EXPECT_GT(p.stats.clamped, 0u);
}

TEST(FapStreamReal, SevenBasicEmotionCommentsAndValues) {
  AFM_REQUIRE_SHARED_DATA();
  Parsed p =
      parse_whole(afmtest::read_file(afmtest::shared_data("fap/crystal/7_basic_emotion.fap")));
  ASSERT_EQ(p.result, AFM_OK) << p.diag.message;
  ASSERT_EQ(p.frames.size(), 7u);
  // Lines 2, 5, 8, 11, 14, 17, 20: "# anger" ... "# neutral".
  EXPECT_EQ(p.stats.comment_lines, 7u);
  // :4 "0 -154.8 -44.8 80 80 ..." (mask :3: FAPs 4-13, ...)
  EXPECT_EQ(p.frames[0].line, 4u);
  EXPECT_EQ(p.frames[0].value[4], -155);
  EXPECT_EQ(p.frames[0].value[5], -45);
  EXPECT_EQ(p.frames[0].value[6], 80);
  // :6 mask "0 0 0 1 1 1 0 1 0 1 0 1 1 ..."; :7 "1 -40 -20 -70 -184.8 -73.2 83.2 83.2 ..."
  EXPECT_EQ(p.frames[1].line, 7u);
  EXPECT_EQ(p.frames[1].mask[7], 0);
  EXPECT_EQ(p.frames[1].value[6], -70);
  EXPECT_EQ(p.frames[1].value[8], -185);
  EXPECT_EQ(p.frames[1].value[10], -73);
  EXPECT_EQ(p.frames[1].value[12], 83);
  // :10 "2 -100 -71.601 ... -160.755 -160.755 ...": lift_l_cheek (41) is
  // unidirectional, so the negative value clamps to 0.
  EXPECT_EQ(p.frames[2].line, 10u);
  EXPECT_EQ(p.frames[2].mask[41], 1);
  EXPECT_EQ(p.frames[2].value[41], 0);
  EXPECT_EQ(p.frames[2].value[12], -72);  // -71.6014
  // :22 "6 10 10 10 ..." the last frame.
  EXPECT_EQ(p.frames[6].number, 6u);
  EXPECT_EQ(p.frames[6].line, 22u);
  EXPECT_EQ(p.frames[6].value[4], 10);
}

TEST(FapStreamReal, JoyCrlfEqualsJoy) {
  AFM_REQUIRE_SHARED_DATA();
  std::string lf = afmtest::read_file(afmtest::shared_data("fap/xface/joy.fap"));
  std::string crlf = afmtest::read_file(afmtest::shared_data("fap/xface/joy-crlf.fap"));
  ASSERT_NE(lf, crlf);
  ASSERT_NE(crlf.find("\r\n"), std::string::npos);
  Parsed a = parse_whole(lf), b = parse_whole(crlf);
  ASSERT_EQ(a.result, AFM_OK);
  expect_same(a, b, "joy.fap vs joy-crlf.fap");
  // Lone CR line ends read the same too.
  std::string cr = lf;
  std::replace(cr.begin(), cr.end(), '\n', '\r');
  expect_same(a, parse_whole(cr), "joy.fap with CR line ends");
}

TEST(FapStreamReal, RandomChunksEqualWholeBuffer) {
  AFM_REQUIRE_SHARED_DATA();
  for (const auto &path : real_fap_files()) {
    std::string text = afmtest::read_file(path);
    Parsed whole = parse_whole(text);
    ASSERT_EQ(whole.result, AFM_OK) << path;
    for (unsigned seed = 1; seed <= 4; ++seed) {
      std::mt19937 rng(seed);
      const size_t max_sizes[] = {2, 9, 300, 5000};
      size_t max_size = max_sizes[seed - 1];
      std::uniform_int_distribution<size_t> dist(1, max_size);
      Parsed chunked = parse_chunks(text, [&] { return dist(rng); });
      expect_same(whole, chunked, path + " seed " + std::to_string(seed));
    }
    expect_same(whole, parse_chunks(text, [] { return size_t{1}; }), path + " bytewise");
  }
}

// ---- synthetic streams ----------------------------------------------------------

TEST(FapStreamSynthetic, VisemeFourAndOneValue) {
  std::string s = "2.1 visemes 25 3\n" + mask({1, 3}) + "\n0 5 7 40 1 100\n" + mask({1, 3}) +
                  "\n1 9 -20\n" + mask({1}) + "\n2 3 4 63 0\n";
  Parsed p = parse_whole(s);
  ASSERT_EQ(p.result, AFM_OK) << p.diag.message;
  ASSERT_EQ(p.frames.size(), 3u);
  const afm_fap_frame &a = p.frames[0];
  EXPECT_EQ(a.mask[1], 1);
  EXPECT_EQ(a.viseme.select1, 5);
  EXPECT_EQ(a.viseme.select2, 7);
  EXPECT_EQ(a.viseme.blend, 40);
  EXPECT_EQ(a.viseme.def, 1);
  EXPECT_EQ(a.value[3], 100);
  // One value: select1 at full blend.
  const afm_fap_frame &b = p.frames[1];
  EXPECT_EQ(b.viseme.select1, 9);
  EXPECT_EQ(b.viseme.select2, 0);
  EXPECT_EQ(b.viseme.blend, 63);
  EXPECT_EQ(b.viseme.def, 0);
  EXPECT_EQ(b.value[3], 0);  // -20 clamped (open_jaw)
  EXPECT_EQ(p.frames[2].viseme.select1, 3);
  EXPECT_EQ(p.frames[2].viseme.select2, 4);
  EXPECT_EQ(p.stats.single_visemes, 1u);
  EXPECT_EQ(p.stats.clamped, 1u);
}

TEST(FapStreamSynthetic, ExpressionSixValues) {
  std::string s = "2.1 expr 25 1\n" + mask({2, 4}) + "\n0 3 50 6 20 1 0 -12\n";
  Parsed p = parse_whole(s);
  ASSERT_EQ(p.result, AFM_OK) << p.diag.message;
  const afm_expression_value &e = p.frames[0].expression;
  EXPECT_EQ(e.select1, 3);
  EXPECT_EQ(e.intensity1, 50);
  EXPECT_EQ(e.select2, 6);
  EXPECT_EQ(e.intensity2, 20);
  EXPECT_EQ(e.init_face, 1);
  EXPECT_EQ(e.def, 0);
  EXPECT_EQ(p.frames[0].value[4], -12);
  EXPECT_EQ(p.frames[0].mask[1], 0);
  EXPECT_EQ(p.frames[0].mask[2], 1);
  // Both high-level FAPs: 4 (or 1) viseme values first, then 6 expression values.
  std::string both = "2.1 both 25 2\n" + mask({1, 2, 5}) + "\n0 1 2 30 0 4 10 0 0 0 1 77\n" +
                     mask({1, 2, 5}) + "\n1 8 5 63 2 0 0 0 -77\n";
  Parsed q = parse_whole(both);
  ASSERT_EQ(q.result, AFM_OK) << q.diag.message;
  EXPECT_EQ(q.frames[0].viseme.blend, 30);
  EXPECT_EQ(q.frames[0].expression.select1, 4);
  EXPECT_EQ(q.frames[0].expression.def, 1);
  EXPECT_EQ(q.frames[0].value[5], 77);
  EXPECT_EQ(q.frames[1].viseme.select1, 8);
  EXPECT_EQ(q.frames[1].viseme.blend, 63);
  EXPECT_EQ(q.frames[1].expression.select1, 5);
  EXPECT_EQ(q.frames[1].expression.intensity1, 63);
  EXPECT_EQ(q.frames[1].value[5], -77);
  EXPECT_EQ(q.stats.single_visemes, 1u);
}

TEST(FapStreamSynthetic, SixtyNineEntryMasks) {
  // 69th bit 0: no extra value; 69th bit 1: one more value at the end, skipped.
  std::string s = "2.1 m69 25 2\n" + mask({3, 68}, 69) + "\n0 11 22\n" + mask({3, 68, 69}, 69) +
                  "\n1 33 44 999\n";
  Parsed p = parse_whole(s);
  ASSERT_EQ(p.result, AFM_OK) << p.diag.message;
  EXPECT_EQ(p.frames[0].value[3], 11);
  EXPECT_EQ(p.frames[0].value[68], 22);
  EXPECT_EQ(p.frames[1].value[3], 33);
  EXPECT_EQ(p.frames[1].value[68], 44);
  EXPECT_EQ(p.stats.masks_69, 2u);
  EXPECT_EQ(p.stats.skipped_values, 1u);
  // The extra value must still be there: without it the count is off.
  Parsed bad = parse_whole("2.1 m69 25 1\n" + mask({3, 69}, 69) + "\n0 11\n");
  EXPECT_EQ(bad.result, AFM_ERR_SYNTAX);
  EXPECT_EQ(bad.diag.line, 3u);
  EXPECT_NE(std::string(bad.diag.message).find("1 values, expected 2"), std::string::npos)
      << bad.diag.message;
}

TEST(FapStreamSynthetic, LayoutVariants) {
  // Comments before the header and trailing ones, blank lines, tabs, CRLF,
  // frames from 1 with a gap, a name with spaces, version 2.2, decimal fps.
  std::string s =
      "# made by hand\r\n"
      "\r\n"
      "2.2   my face, take 3\t29.97 3 # trailing comment\r\n" +
      mask({3, 4}, 68, "\t") + "\t\r\n" +
      "1\t10\t-20  # values\r\n"
      "   \t \r\n"
      "# between frames\r\n" +
      mask({4}) + "\r\n2 7\r\n" + mask({4}) + "\r\n9 -7";  // no line end at the end
  Parsed p = parse_whole(s);
  ASSERT_EQ(p.result, AFM_OK) << p.diag.message;
  EXPECT_EQ(p.header.version_major, 2);
  EXPECT_EQ(p.header.version_minor, 2);
  EXPECT_STREQ(p.header.name, "my face, take 3");
  EXPECT_EQ(p.header.fps_num, 2997u);
  EXPECT_EQ(p.header.fps_den, 100u);
  EXPECT_EQ(p.header.frame_count, 3u);
  ASSERT_EQ(p.frames.size(), 3u);
  EXPECT_EQ(p.frames[0].number, 1u);
  EXPECT_EQ(p.frames[0].line, 5u);
  EXPECT_EQ(p.frames[0].value[3], 10);
  EXPECT_EQ(p.frames[0].value[4], -20);
  EXPECT_EQ(p.frames[1].number, 2u);
  EXPECT_EQ(p.frames[1].line, 9u);
  EXPECT_EQ(p.frames[1].mask[3], 0);
  EXPECT_EQ(p.frames[1].value[3], 0);  // not sent in this frame
  EXPECT_EQ(p.frames[2].number, 9u);   // gaps allowed
  EXPECT_EQ(p.frames[2].line, 11u);
  EXPECT_EQ(p.frames[2].value[4], -7);
  EXPECT_EQ(p.stats.comment_lines, 2u);
  // The same with LF and with lone CR line ends, and fed byte by byte.
  std::string lf = s, cr = s;
  lf.erase(std::remove(lf.begin(), lf.end(), '\r'), lf.end());
  cr.erase(std::remove(cr.begin(), cr.end(), '\n'), cr.end());
  expect_same(p, parse_whole(lf), "LF");
  expect_same(p, parse_whole(cr), "CR");
  expect_same(p, parse_chunks(s, [] { return size_t{1}; }), "CRLF bytewise");
  expect_same(p, parse_chunks(cr, [] { return size_t{1}; }), "CR bytewise");
}

TEST(FapStreamSynthetic, HeaderForms) {
  struct {
    const char *header;
    uint8_t minor;
    uint32_t num, den;
    const char *name;
  } cases[] = {
      {"2.0 a 25 1", 0, 25, 1, "a"},
      {"2.1 a 30.0 1", 1, 30, 1, "a"},
      {"2.2 a 12.50 1", 2, 25, 2, "a"},
      {"2.1 a 29.97 1", 1, 2997, 100, "a"},
      {"2.1 25 1", 1, 25, 1, ""},
      {"2.1 a  b\tc 25 1", 1, 25, 1, "a  b\tc"},
      {"\xEF\xBB\xBF" "2.1 a 25 1", 1, 25, 1, "a"},  // UTF-8 byte order mark
      {"2.1 a 0.5 1", 1, 1, 2, "a"},
  };
  for (const auto &c : cases) {
    SCOPED_TRACE(c.header);
    Parsed p = parse_whole(std::string(c.header) + "\n" + mask({}) + "\n0\n");
    ASSERT_EQ(p.result, AFM_OK) << p.diag.message;
    EXPECT_EQ(p.header.version_minor, c.minor);
    EXPECT_EQ(p.header.fps_num, c.num);
    EXPECT_EQ(p.header.fps_den, c.den);
    EXPECT_STREQ(p.header.name, c.name);
  }
}

TEST(FapStreamSynthetic, NumberFormsAndRounding) {
  struct {
    const char *text;
    int32_t value;
    bool fractional;
  } cases[] = {
      {"7", 7, false},          {"+7", 7, false},         {"-7", -7, false},
      {"10.", 10, false},       {"10.000", 10, false},    {".5", 1, true},
      {"-.5", -1, true},        {"0.5", 1, true},         {"-0.5", -1, true},
      {"2.5", 3, true},         {"-2.5", -3, true},       {"2.4999", 2, true},
      {"-2.5001", -3, true},    {"-0.4", 0, true},        {"1e2", 100, false},
      {"1E+2", 100, false},     {"-2.5e-1", 0, true},     {"25e-1", 3, true},
      {"1.29641e-05", 0, true}, {"1e+06", 16384, false},  {"-1e999999", -16384, false},
      {"1e-999999", 0, true},   {"000012", 12, false},    {"0.49999999999999999999", 0, true},
      {"0.50000000000000000000001", 1, true},  {"1234.5000000000000000000000", 1235, true},
      {"16384.4", 16384, true}, {"16384.5", 16384, true}, // clamped after rounding
      {"123456789012345678901234567890", 16384, false},
      {"-0", 0, false},         {"0e5", 0, false},
  };
  for (const auto &c : cases) {
    SCOPED_TRACE(c.text);
    Parsed p = parse_whole("2.1 n 25 1\n" + mask({4}) + "\n0 " + c.text + "\n");
    ASSERT_EQ(p.result, AFM_OK) << p.diag.message;
    EXPECT_EQ(p.frames[0].value[4], c.value);
    EXPECT_EQ(p.stats.rounded, c.fractional ? 1u : 0u);
  }
}

TEST(FapStreamSynthetic, ClampingPerFap) {
  std::string s = "2.1 clamp 25 1\n" + mask({1, 2, 3, 4, 14, 23, 41, 47, 48}) +
                  "\n0 20 -1 70 2  9 64 -1 99 3 -3  -5 -20000 -1 400000 -2 -1 -400000\n";
  Parsed p = parse_whole(s);
  ASSERT_EQ(p.result, AFM_OK) << p.diag.message;
  const afm_fap_frame &f = p.frames[0];
  EXPECT_EQ(f.viseme.select1, 14);  // viseme 20 -> 14
  EXPECT_EQ(f.viseme.select2, 0);   // -1 -> 0
  EXPECT_EQ(f.viseme.blend, 63);    // 70 -> 63
  EXPECT_EQ(f.viseme.def, 1);       // 2 -> 1
  EXPECT_EQ(f.expression.select1, 6);
  EXPECT_EQ(f.expression.intensity1, 63);
  EXPECT_EQ(f.expression.select2, 0);
  EXPECT_EQ(f.expression.intensity2, 63);
  EXPECT_EQ(f.expression.init_face, 1);
  EXPECT_EQ(f.expression.def, 0);
  EXPECT_EQ(f.value[3], 0);         // open_jaw -5 -> 0
  EXPECT_EQ(f.value[4], -16384);    // -20000
  EXPECT_EQ(f.value[14], 0);        // thrust_jaw -1
  EXPECT_EQ(f.value[23], 314159);   // 400000 AU
  EXPECT_EQ(f.value[41], 0);        // lift_l_cheek -2
  EXPECT_EQ(f.value[47], 0);        // tongue_roll -1
  EXPECT_EQ(f.value[48], -314159);
  EXPECT_EQ(p.stats.clamped, 17u);
}

TEST(FapStreamSynthetic, ValueRangesFollowTheReferenceTable) {
  AFM_REQUIRE_SHARED_REFERENCE();
  afmtest::CsvTable t = afmtest::read_csv(afmtest::shared_reference("mpeg4-fap-table.csv"));
  ASSERT_TRUE(t.error.empty()) << t.error;
  int checked = 0;
  for (auto &row : t.rows) {
    int fap = std::stoi(row["fap"]);
    int32_t lo = 1, hi = 1;
    if (fap <= 2) {
      EXPECT_EQ(afm_fap_value_range(fap, &lo, &hi), 0);
      continue;
    }
    SCOPED_TRACE("FAP " + row["fap"]);
    ASSERT_EQ(afm_fap_value_range(fap, &lo, &hi), 1);
    int32_t limit = row["fapu"] == "AU" ? 314159 : 16384;
    EXPECT_EQ(hi, limit);
    EXPECT_EQ(lo, row["uni_bi"] == "U" ? 0 : -limit);
    ++checked;
  }
  EXPECT_EQ(checked, 66);
  int32_t lo = 7, hi = 7;
  EXPECT_EQ(afm_fap_value_range(0, &lo, &hi), 0);
  EXPECT_EQ(afm_fap_value_range(69, &lo, &hi), 0);
  EXPECT_EQ(lo, 7);
  EXPECT_EQ(afm_fap_value_range(3, nullptr, &hi), 1);
  EXPECT_EQ(hi, 16384);
}

TEST(FapStreamSynthetic, Version20DivideBy20) {
  std::string body = mask({1, 3, 4, 48}) + "\n0 10 0 20 0 100 -30 9\n" + mask({4}) + "\n1 10\n";
  Parsed off = parse_whole("2.0 v 25 2\n" + body);
  ASSERT_EQ(off.result, AFM_OK) << off.diag.message;
  EXPECT_EQ(off.frames[0].value[3], 100);
  EXPECT_EQ(off.frames[0].value[4], -30);
  Parsed on = parse_whole("2.0 v 25 2\n" + body, AFM_FAP_V20_DIVIDE_BY_20);
  ASSERT_EQ(on.result, AFM_OK) << on.diag.message;
  EXPECT_EQ(on.frames[0].viseme.select1, 10);  // FAP 1 fields are not divided
  EXPECT_EQ(on.frames[0].viseme.blend, 20);
  EXPECT_EQ(on.frames[0].value[3], 5);   // 100 / 20
  EXPECT_EQ(on.frames[0].value[4], -2);  // -1.5 -> -2
  EXPECT_EQ(on.frames[0].value[48], 0);  // 0.45 -> 0
  EXPECT_EQ(on.frames[1].value[4], 1);   // 0.5 -> 1
  EXPECT_EQ(on.stats.rounded, 3u);
  // Only version 2.0 streams are divided.
  Parsed v21 = parse_whole("2.1 v 25 2\n" + body, AFM_FAP_V20_DIVIDE_BY_20);
  ASSERT_EQ(v21.result, AFM_OK);
  EXPECT_EQ(v21.frames[0].value[3], 100);
  // Divided exactly before rounding: 10.1 / 20 = 0.505 -> 1; 9.9 / 20 -> 0.
  Parsed exact = parse_whole("2.0 v 25 1\n" + mask({4, 5}) + "\n0 10.1 9.9\n",
                             AFM_FAP_V20_DIVIDE_BY_20);
  ASSERT_EQ(exact.result, AFM_OK);
  EXPECT_EQ(exact.frames[0].value[4], 1);
  EXPECT_EQ(exact.frames[0].value[5], 0);
}

// ---- errors ----------------------------------------------------------------------

struct BadCase {
  const char *what;
  std::string text;
  afm_result result;
  uint32_t line;
  const char *message_part;
};

// Byte offset of line `n` (1-based) of `text`, with LF, CRLF or CR line ends.
size_t line_start(const std::string &text, uint32_t n) {
  size_t at = 0;
  for (uint32_t line = 1; line < n && at < text.size(); ++line) {
    size_t e = text.find_first_of("\r\n", at);
    if (e == std::string::npos) return text.size();
    at = e + ((text[e] == '\r' && e + 1 < text.size() && text[e + 1] == '\n') ? 2 : 1);
  }
  return at;
}

void expect_error(const BadCase &c) {
  SCOPED_TRACE(c.what);
  Parsed p = parse_whole(c.text);
  // The offset is the named line's start, or the stream's length for the
  // end-of-stream checks.
  const bool at_end = std::string(p.diag.message).find("the stream ends") != std::string::npos;
  EXPECT_EQ(p.diag.offset, at_end ? c.text.size() : line_start(c.text, c.line));
  EXPECT_EQ(p.result, c.result) << afm_result_string(p.result) << ": " << p.diag.message;
  EXPECT_EQ(p.diag.line, c.line) << p.diag.message;
  EXPECT_NE(std::string(p.diag.message).find(c.message_part), std::string::npos)
      << p.diag.message;
  std::string prefix = "line " + std::to_string(c.line) + ": ";
  EXPECT_EQ(std::string(p.diag.message).rfind(prefix, 0), 0u) << p.diag.message;
  // Same error fed in pieces.
  Parsed q = parse_chunks(c.text, [] { return size_t{3}; });
  EXPECT_EQ(q.result, p.result);
  EXPECT_STREQ(q.diag.message, p.diag.message);
}

TEST(FapStreamErrors, EachNamesItsLine) {
  const std::string h = "2.1 bad 25 2\n";
  const std::string m4 = mask({4});
  std::string mask67 = m4.substr(0, m4.size() - 2);
  std::string mask70 = mask({4}) + " 0 0";
  std::string mask_two = mask({4});
  mask_two[2 * 9] = '2';  // entry 10
  std::string long_line = h + m4 + "\n0 1" + std::string(AFM_FAP_MAX_LINE, ' ') + "\n";
  std::vector<BadCase> cases = {
      {"version 3.0", "3.0 x 25 1\n", AFM_ERR_SYNTAX, 1, "version '3.0' not supported"},
      {"version 2.3 after a comment", "# c\n2.3 x 25 1\n", AFM_ERR_SYNTAX, 2, "version"},
      {"version 2", "2 x 25 1\n", AFM_ERR_SYNTAX, 1, "version"},
      {"header fields", "2.1 25\n", AFM_ERR_SYNTAX, 1, "header has 2 fields"},
      {"fps 0", "2.1 x 0 1\n", AFM_ERR_SYNTAX, 1, "frame rate '0'"},
      {"fps text", "2.1 x 2x5 1\n", AFM_ERR_SYNTAX, 1, "frame rate '2x5'"},
      {"fps negative", "2.1 x -25 1\n", AFM_ERR_SYNTAX, 1, "frame rate"},
      {"frame count", "2.1 x 25 1.5\n", AFM_ERR_SYNTAX, 1, "frame count '1.5'"},
      {"short mask", h + mask67 + "\n0 1\n", AFM_ERR_SYNTAX, 2,
       "mask has 67 entries, expected 68 or 69"},
      {"long mask", h + mask70 + "\n0 1\n", AFM_ERR_SYNTAX, 2, "mask has 70 entries"},
      {"mask entry 2", h + mask_two + "\n0 1\n", AFM_ERR_SYNTAX, 2,
       "mask entry 10 is '2', expected 0 or 1"},
      {"mask entry 1.0", h + "1.0" + m4.substr(1) + "\n0 1\n", AFM_ERR_SYNTAX, 2,
       "mask entry 1 is '1.0'"},
      {"too few values", h + mask({4, 5, 6}) + "\n0 1 2\n", AFM_ERR_SYNTAX, 3,
       "2 values, expected 3"},
      {"too many values", h + m4 + "\n0 1 2 3\n", AFM_ERR_SYNTAX, 3, "3 values, expected 1"},
      {"viseme count", h + mask({1, 4}) + "\n0 1 2 3\n", AFM_ERR_SYNTAX, 3,
       "3 values, expected 5 (FAP 1 as 4 values) or 2 (FAP 1 as 1 value)"},
      {"expression count", h + mask({2}) + "\n0 1 2 3 4 5\n", AFM_ERR_SYNTAX, 3,
       "5 values, expected 6"},
      {"not a number", h + m4 + "\n0 abc\n", AFM_ERR_SYNTAX, 3, "value 1 ('abc') is not a number"},
      {"two dots", h + mask({4, 5}) + "\n0 1 1.2.3\n", AFM_ERR_SYNTAX, 3, "value 2 ('1.2.3')"},
      {"lone dot", h + m4 + "\n0 .\n", AFM_ERR_SYNTAX, 3, "not a number"},
      {"double sign", h + m4 + "\n0 --1\n", AFM_ERR_SYNTAX, 3, "not a number"},
      {"bare exponent", h + m4 + "\n0 1e\n", AFM_ERR_SYNTAX, 3, "not a number"},
      {"nan", h + m4 + "\n0 nan\n", AFM_ERR_SYNTAX, 3, "not a number"},
      {"comma", h + m4 + "\n0 2,5\n", AFM_ERR_SYNTAX, 3, "not a number"},
      {"frame number text", h + m4 + "\nx 1\n", AFM_ERR_SYNTAX, 3, "frame number 'x'"},
      {"frame number negative", h + m4 + "\n-1 1\n", AFM_ERR_SYNTAX, 3, "frame number '-1'"},
      {"frame number decreasing", h + m4 + "\n5 1\n" + m4 + "\n4 1\n", AFM_ERR_SYNTAX, 5,
       "frame number 4 after 5"},
      {"frame number repeated", h + m4 + "\n5 1\n" + m4 + "\n5 1\n", AFM_ERR_SYNTAX, 5,
       "frame number 5 after 5"},
      {"more frames than stated", h + m4 + "\n0 1\n# x\n" + m4 + "\n1 1\n" + m4 + "\n2 1\n",
       AFM_ERR_SYNTAX, 7, "more frames than the 2 the header states"},
      {"line too long", long_line, AFM_ERR_LIMIT, 3, "longer than 4096 bytes"},
      {"mask without values", h + m4 + "\n0 1\n" + m4 + "\n# end\n", AFM_ERR_TRUNCATED, 4,
       "without its value line"},
      {"fewer frames", h + m4 + "\n0 1\n", AFM_ERR_TRUNCATED, 3, "after 1 of the 2 frames"},
      {"empty", "", AFM_ERR_TRUNCATED, 1, "before its header"},
      {"comments only", "# a\n\n# b\n", AFM_ERR_TRUNCATED, 3, "before its header"},
      {"cut last line", h + m4 + "\n0 1\n" + m4 + "\n1 -", AFM_ERR_TRUNCATED, 5,
       "value 1 ('-') is not a number (the last line has no line end"},
  };
  for (const auto &c : cases) expect_error(c);
}

TEST(FapStreamErrors, LongLineFedInPiecesFailsEarly) {
  afm_diag diag{};
  auto reader = std::make_unique<afm_fap_reader>();
  afm_fap_reader_init(reader.get(), nullptr, &diag);
  std::string head = "2.1 x 25 1\n";
  afm_fap_frame f;
  size_t used = 0;
  int has = 0;
  ASSERT_EQ(afm_fap_reader_feed(reader.get(), reinterpret_cast<const uint8_t *>(head.data()),
                                head.size(), &used, &f, &has),
            AFM_OK);
  std::string spaces(1000, ' ');
  afm_result r = AFM_OK;
  int calls = 0;
  while (r == AFM_OK && calls < 100) {
    r = afm_fap_reader_feed(reader.get(), reinterpret_cast<const uint8_t *>(spaces.data()),
                            spaces.size(), &used, &f, &has);
    ++calls;
  }
  EXPECT_EQ(r, AFM_ERR_LIMIT);
  EXPECT_EQ(calls, 5);  // 5000 bytes > 4096 without a line end
  EXPECT_EQ(diag.line, 2u);
  // Sticky.
  EXPECT_EQ(afm_fap_reader_feed(reader.get(), reinterpret_cast<const uint8_t *>("\n"), 1, &used,
                                &f, &has),
            AFM_ERR_LIMIT);
  EXPECT_EQ(afm_fap_reader_finish(reader.get(), &f, &has), AFM_ERR_LIMIT);
}

TEST(FapStreamErrors, EveryPrefixIsShorterParseOrTruncated) {
  std::string s = "# small\n2.1 small 25 3\n" + mask({1, 3, 48}) +
                  "\n0 5 6 40 0 12.5 -3000\n" + mask({2, 4}, 69) + "\r\n1 3 20 0 0 0 0 -7\r\n" +
                  mask({1, 5, 69}, 69) + "\n2 4 1e1 .5 # end\n# tail\n";
  Parsed full = parse_whole(s);
  ASSERT_EQ(full.result, AFM_OK) << full.diag.message;
  ASSERT_EQ(full.frames.size(), 3u);
  for (size_t n = 0; n <= s.size(); ++n) {
    SCOPED_TRACE("prefix of " + std::to_string(n) + " bytes");
    Parsed p = parse_whole(s.substr(0, n));
    ASSERT_TRUE(p.result == AFM_OK || p.result == AFM_ERR_TRUNCATED)
        << afm_result_string(p.result) << ": " << p.diag.message;
    ASSERT_LE(p.frames.size(), full.frames.size());
    if (p.result == AFM_OK) {
      EXPECT_EQ(p.frames.size(), full.frames.size());
    }
    // Frames before the last one read are those of the whole file (the last
    // may come from a cut last line, "2 4 1" of "2 4 1e1").
    for (size_t i = 0; i + 1 < p.frames.size(); ++i)
      EXPECT_TRUE(same_frame(p.frames[i], full.frames[i])) << i;
    if (p.result == AFM_ERR_TRUNCATED) {
      EXPECT_GE(p.diag.line, 1u);
      EXPECT_LE(p.diag.line, 11u);
    }
  }
}

TEST(FapStreamErrors, Arguments) {
  afm_fap_frame f;
  size_t used = 7;
  int has = 7;
  auto reader = std::make_unique<afm_fap_reader>();
  afm_fap_reader_init(reader.get(), nullptr, nullptr);
  EXPECT_EQ(afm_fap_reader_header(reader.get()), nullptr);
  EXPECT_EQ(afm_fap_reader_feed(nullptr, nullptr, 0, &used, &f, &has), AFM_ERR_ARGUMENT);
  EXPECT_EQ(used, 0u);
  EXPECT_EQ(has, 0);
  EXPECT_EQ(afm_fap_reader_feed(reader.get(), nullptr, 1, &used, &f, &has), AFM_ERR_ARGUMENT);
  EXPECT_EQ(afm_fap_reader_feed(reader.get(), nullptr, 0, &used, nullptr, &has),
            AFM_ERR_ARGUMENT);
  EXPECT_EQ(afm_fap_reader_finish(reader.get(), &f, nullptr), AFM_ERR_ARGUMENT);
  // Argument errors are not sticky: the reader still works.
  EXPECT_EQ(afm_fap_reader_feed(reader.get(), nullptr, 0, &used, &f, &has), AFM_OK);
  // Unknown flags.
  afm_fap_reader_options opt{};
  opt.flags = 0x80;
  uint32_t count = 5;
  const uint8_t one[] = {'2'};
  EXPECT_EQ(afm_fap_parse(one, 1, &opt, nullptr, 0, &count, nullptr, nullptr, nullptr),
            AFM_ERR_ARGUMENT);
  EXPECT_EQ(count, 0u);
  EXPECT_EQ(afm_fap_parse(one, 1, nullptr, nullptr, 0, nullptr, nullptr, nullptr, nullptr),
            AFM_ERR_ARGUMENT);
  // Feeding a finished reader.
  std::string s = "2.1 x 25 1\n" + mask({}) + "\n0\n";
  ASSERT_EQ(afm_fap_reader_feed(reader.get(), reinterpret_cast<const uint8_t *>(s.data()),
                                s.size(), &used, &f, &has),
            AFM_OK);
  EXPECT_EQ(has, 1);
  EXPECT_EQ(used, s.size());
  EXPECT_EQ(afm_fap_reader_finish(reader.get(), &f, &has), AFM_OK);
  EXPECT_EQ(has, 0);
  EXPECT_EQ(afm_fap_reader_finish(reader.get(), &f, &has), AFM_OK);
  EXPECT_EQ(afm_fap_reader_feed(reader.get(), one, 1, &used, &f, &has), AFM_ERR_STATE);
  ASSERT_NE(afm_fap_reader_header(reader.get()), nullptr);
  EXPECT_EQ(afm_fap_reader_stats(reader.get())->frames, 1u);
}

TEST(FapStreamErrors, BufferTooSmallCountsAll) {
  std::string s = "2.1 x 25 4\n";
  for (int i = 0; i < 4; ++i) s += mask({4}) + "\n" + std::to_string(i) + " " + std::to_string(i * 10) + "\n";
  std::vector<afm_fap_frame> frames(2);
  uint32_t count = 0;
  afm_result r = afm_fap_parse(reinterpret_cast<const uint8_t *>(s.data()), s.size(), nullptr,
                               frames.data(), 2, &count, nullptr, nullptr, nullptr);
  EXPECT_EQ(r, AFM_ERR_BUFFER_TOO_SMALL);
  EXPECT_EQ(count, 4u);
  EXPECT_EQ(frames[1].value[4], 10);
  // A later syntax error wins over "too small".
  std::string bad = s + "junk\n";
  r = afm_fap_parse(reinterpret_cast<const uint8_t *>(bad.data()), bad.size(), nullptr,
                    frames.data(), 2, &count, nullptr, nullptr, nullptr);
  EXPECT_EQ(r, AFM_ERR_SYNTAX);
}

}  // namespace
