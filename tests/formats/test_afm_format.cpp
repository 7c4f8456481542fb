// AFM container and codec: round trips, profiles, damage and bad input.
#include <afm/draco.h>
#include <afm/format.h>
#include <gtest/gtest.h>

#include <cstring>
#include <memory>
#include <random>

#include "../common/synthetic_doc.h"

using afmtest::compare_docs;
using afmtest::make_synthetic_doc;
using afmtest::SyntheticDoc;
using afmtest::write_doc;

namespace {

struct Freer {
  void operator()(afm_doc *d) const { afm_free(nullptr, d); }
};
using DocPtr = std::unique_ptr<afm_doc, Freer>;

afm_result read(const std::vector<uint8_t> &bytes, DocPtr *doc, afm_diag *diag = nullptr,
                const afm_chunk_codec *draco = afm_draco_codec()) {
  afm_read_options ro{};
  ro.draco = draco;
  ro.diag = diag;
  afm_doc *d = nullptr;
  afm_result r = afm_doc_read_alloc(bytes.data(), bytes.size(), &ro, nullptr, &d);
  doc->reset(d);
  return r;
}

uint32_t le32(const uint8_t *p) { return p[0] | p[1] << 8 | p[2] << 16 | uint32_t(p[3]) << 24; }
void put32(uint8_t *p, uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = uint8_t(v >> (8 * i));
}

// Re-seals the header CRC after a test edits the header or table.
void reseal_header(std::vector<uint8_t> &f) {
  uint32_t count = le32(&f[12]);
  size_t end = 16 + 20 * size_t(count);
  put32(&f[end], afm_crc32(f.data(), end));
}

// Re-seals chunk i's CRC after a test edits its payload.
void reseal_chunk(std::vector<uint8_t> &f, uint32_t i) {
  uint8_t *e = &f[16 + 20 * size_t(i)];
  put32(e + 16, afm_crc32(&f[le32(e + 8)], le32(e + 12)));
  reseal_header(f);
}

// Calls edit(info) on the file's first chunk of `kind`, whose payload it may
// change in place (f[info.offset ...]), then reseals its CRC. False when the
// file does not open or has no such chunk.
template <class Edit>
bool edit_chunk(std::vector<uint8_t> &f, uint32_t kind, Edit edit) {
  afm_container c;
  if (afm_container_open(f.data(), f.size(), &c, nullptr) != AFM_OK) return false;
  for (uint32_t i = 0; i < c.chunk_count; ++i) {
    afm_chunk_info ch;
    afm_container_chunk(&c, i, &ch);
    if (ch.kind != kind) continue;
    edit(ch);
    reseal_chunk(f, i);
    return true;
  }
  return false;
}

// Encoding (0 raw, 1 draco) of the chunk of this kind.
int chunk_encoding(const std::vector<uint8_t> &f, uint32_t kind) {
  afm_container c;
  if (afm_container_open(f.data(), f.size(), &c, nullptr) != AFM_OK) return -1;
  for (uint32_t i = 0; i < c.chunk_count; ++i) {
    afm_chunk_info ch;
    afm_container_chunk(&c, i, &ch);
    if (ch.kind == kind) return ch.encoding;
  }
  return -1;
}

// A way to spoil a valid synthetic document, and what the writer must say.
struct SpoilCase {
  const char *what;
  void (*spoil)(SyntheticDoc &);
  const char *message;
};

// Each case spoils a fresh synthetic document (options `o`); the writer,
// which validates as the reader does, must refuse it, write nothing and
// name the problem.
void expect_writer_refuses(const SpoilCase *cases, size_t count, const afmtest::SyntheticOptions &o) {
  for (size_t i = 0; i < count; ++i) {
    const SpoilCase &c = cases[i];
    SyntheticDoc s;
    make_synthetic_doc(s, o);
    c.spoil(s);
    afm_write_options wo{};
    afm_diag diag{};
    wo.diag = &diag;
    uint8_t *out = nullptr;
    size_t n = 0;
    EXPECT_NE(afm_doc_write(&s.doc, &wo, &out, &n), AFM_OK) << c.what;
    EXPECT_EQ(out, nullptr) << c.what;
    EXPECT_NE(std::string(diag.message).find(c.message), std::string::npos) << c.what << ": " << diag.message;
  }
}

}  // namespace

TEST(AfmFormat, RawRoundTripKeepsEveryField) {
  SyntheticDoc s;
  const afm_doc *src = make_synthetic_doc(s);
  std::vector<uint8_t> bytes = write_doc(*src, AFM_PROFILE_RAW);
  DocPtr doc;
  afm_diag diag{};
  ASSERT_EQ(read(bytes, &doc, &diag), AFM_OK) << diag.message;
  EXPECT_EQ(compare_docs(*src, *doc), "");
  EXPECT_EQ(doc->skipped_chunks, 0u);
  // Writing what we read gives the same bytes: the encoding is canonical.
  EXPECT_EQ(write_doc(*doc, AFM_PROFILE_RAW), bytes);
}

// Each distance unit reads its own X0 (distinct values, so a swap shows);
// angles and the high-level FAPs have none.
TEST(AfmFormat, EachFapUnitReadsItsOwnDistance) {
  afm_meta m{};
  m.es0 = 1, m.irisd0 = 2, m.ens0 = 3, m.mns0 = 4, m.mw0 = 5;
  EXPECT_EQ(afm_meta_fapu_x0(&m, AFM_FAPU_ES), 1);
  EXPECT_EQ(afm_meta_fapu_x0(&m, AFM_FAPU_IRISD), 2);
  EXPECT_EQ(afm_meta_fapu_x0(&m, AFM_FAPU_ENS), 3);
  EXPECT_EQ(afm_meta_fapu_x0(&m, AFM_FAPU_MNS), 4);
  EXPECT_EQ(afm_meta_fapu_x0(&m, AFM_FAPU_MW), 5);
  EXPECT_EQ(afm_meta_fapu_x0(&m, AFM_FAPU_AU), 0);
  EXPECT_EQ(afm_meta_fapu_x0(&m, AFM_FAPU_NONE), 0);
}

TEST(AfmFormat, BufferApiMatchesAllocatingApi) {
  SyntheticDoc s;
  std::vector<uint8_t> bytes = write_doc(*make_synthetic_doc(s), AFM_PROFILE_RAW);
  size_t need = 0;
  ASSERT_EQ(afm_doc_measure(bytes.data(), bytes.size(), nullptr, &need), AFM_OK);
  std::vector<uint64_t> buf(need / 8 + 1);
  afm_doc *doc = nullptr;
  EXPECT_EQ(afm_doc_read(bytes.data(), bytes.size(), nullptr, buf.data(), need - 8, &doc),
            AFM_ERR_BUFFER_TOO_SMALL);
  ASSERT_EQ(afm_doc_read(bytes.data(), bytes.size(), nullptr, buf.data(), need, &doc), AFM_OK);
  EXPECT_EQ(compare_docs(s.doc, *doc), "");
  // A raw file needs no codec at all.
  afm_read_options ro{};
  EXPECT_EQ(afm_doc_measure(bytes.data(), bytes.size(), &ro, &need), AFM_OK);
}

TEST(AfmFormat, WriterCanonicalisesTriangleOrder) {
  SyntheticDoc canonical, shuffled;
  afmtest::SyntheticOptions o;
  make_synthetic_doc(canonical);
  o.shuffle_triangles = true;
  const afm_doc *src = make_synthetic_doc(shuffled, o);
  ASSERT_NE(shuffled.tris, canonical.tris);
  DocPtr doc;
  ASSERT_EQ(read(write_doc(*src, AFM_PROFILE_RAW), &doc), AFM_OK);
  EXPECT_EQ(compare_docs(canonical.doc, *doc), "");
}

TEST(AfmFormat, RawAndDracoConvertExactly) {
  for (int variant = 0; variant < 3; ++variant) {
    const bool attrs = variant != 1;
    SyntheticDoc s;
    afmtest::SyntheticOptions o;
    o.normals = o.texcoords = o.colors = o.normal_deltas = attrs;
    o.loose_vertex = variant == 2;  // edgebreaker drops it: it travels beside the stream
    o.in_betweens = o.combination = variant == 0;
    o.rows = 60, o.cols = 80;
    const afm_doc *src = make_synthetic_doc(s, o);
    std::vector<uint8_t> raw = write_doc(*src, AFM_PROFILE_RAW);
    std::vector<uint8_t> draco = write_doc(*src, AFM_PROFILE_DRACO);
    EXPECT_EQ(chunk_encoding(draco, AFM_CHUNK_GEOM), AFM_ENCODING_DRACO) << "variant " << variant;
    EXPECT_LT(draco.size(), raw.size());
    DocPtr from_draco;
    afm_diag diag{};
    ASSERT_EQ(read(draco, &from_draco, &diag), AFM_OK) << diag.message;
    EXPECT_EQ(compare_docs(*src, *from_draco), "");

    // draco -> raw gives the raw file byte for byte; raw -> draco -> raw too.
    uint8_t *out = nullptr;
    size_t n = 0;
    ASSERT_EQ(afm_transcode(draco.data(), draco.size(), AFM_PROFILE_RAW, afm_draco_codec(), nullptr,
                            &out, &n, &diag),
              AFM_OK)
        << diag.message;
    EXPECT_EQ(std::vector<uint8_t>(out, out + n), raw);
    afm_free(nullptr, out);
    ASSERT_EQ(afm_transcode(raw.data(), raw.size(), AFM_PROFILE_DRACO, afm_draco_codec(), nullptr,
                            &out, &n, &diag),
              AFM_OK);
    EXPECT_EQ(std::vector<uint8_t>(out, out + n), draco);
    afm_free(nullptr, out);
  }
}

TEST(AfmFormat, DracoFileWithoutCodecSaysSo) {
  SyntheticDoc s;
  afmtest::SyntheticOptions o;
  o.rows = 60, o.cols = 80;
  std::vector<uint8_t> draco = write_doc(*make_synthetic_doc(s, o), AFM_PROFILE_DRACO);
  DocPtr doc;
  afm_diag diag{};
  EXPECT_EQ(read(draco, &doc, &diag, nullptr), AFM_ERR_NEED_DRACO);
  EXPECT_NE(std::string(diag.message).find("afm-pack --raw"), std::string::npos) << diag.message;
}

TEST(AfmFormat, EveryPrefixIsRejected) {
  for (afm_profile profile : {AFM_PROFILE_RAW, AFM_PROFILE_DRACO}) {
    SyntheticDoc s;
    afmtest::SyntheticOptions o;
    o.rows = 8, o.cols = 10;
    std::vector<uint8_t> bytes = write_doc(*make_synthetic_doc(s, o), profile);
    for (size_t n = 0; n < bytes.size(); ++n) {
      std::vector<uint8_t> prefix(bytes.begin(), bytes.begin() + n);
      DocPtr doc;
      afm_result r = read(prefix, &doc);
      ASSERT_NE(r, AFM_OK) << "prefix of " << n << " bytes accepted";
      ASSERT_EQ(doc, nullptr);
    }
  }
}

TEST(AfmFormat, CorruptionIsDetected) {
  SyntheticDoc s;
  std::vector<uint8_t> good = write_doc(*make_synthetic_doc(s), AFM_PROFILE_RAW);
  afm_container c;
  ASSERT_EQ(afm_container_open(good.data(), good.size(), &c, nullptr), AFM_OK);
  for (uint32_t i = 0; i < c.chunk_count; ++i) {
    afm_chunk_info ch;
    afm_container_chunk(&c, i, &ch);
    std::vector<uint8_t> bad = good;
    bad[ch.offset + ch.length / 2] ^= 0x10;
    DocPtr doc;
    afm_diag diag{};
    EXPECT_EQ(read(bad, &doc, &diag), AFM_ERR_CHUNK_CRC) << "chunk " << i;
    EXPECT_EQ(diag.chunk, ch.kind);
  }
  std::vector<uint8_t> bad = good;
  bad[16 + 4] ^= 1;  // a chunk's flags in the table
  DocPtr doc;
  EXPECT_EQ(read(bad, &doc), AFM_ERR_HEADER_CRC);
  bad = good;
  bad[1] = 'B';
  EXPECT_EQ(read(bad, &doc), AFM_ERR_MAGIC);
  bad = good;
  bad[8] = 2;  // major version 2
  reseal_header(bad);
  EXPECT_EQ(read(bad, &doc), AFM_ERR_VERSION);
  bad = good;
  bad.insert(bad.end(), {0, 0, 0, 0});
  EXPECT_EQ(read(bad, &doc), AFM_ERR_TRAILING_BYTES);
}

// Inserts a chunk of `kind` with `flags` before the first one.
std::vector<uint8_t> with_extra_chunk(const std::vector<uint8_t> &good, uint32_t kind,
                                      uint16_t flags, uint16_t encoding) {
  afm_container c;
  EXPECT_EQ(afm_container_open(good.data(), good.size(), &c, nullptr), AFM_OK);
  std::vector<afm_chunk_out> chunks;
  static const uint8_t payload[8] = {1, 2, 3, 4, 5, 6, 7, 8};
  chunks.push_back({kind, flags, encoding, payload, sizeof payload});
  for (uint32_t i = 0; i < c.chunk_count; ++i) {
    afm_chunk_info ch;
    afm_container_chunk(&c, i, &ch);
    chunks.push_back({ch.kind, ch.flags, ch.encoding, ch.data, ch.length});
  }
  size_t n = 0;
  EXPECT_EQ(afm_container_size(chunks.data(), uint32_t(chunks.size()), &n), AFM_OK);
  std::vector<uint8_t> out(n);
  EXPECT_EQ(afm_container_write(chunks.data(), uint32_t(chunks.size()), out.data(), n), AFM_OK);
  return out;
}

TEST(AfmFormat, UnknownOptionalChunkIsSkippedRequiredRefused) {
  SyntheticDoc s;
  const afm_doc *src = make_synthetic_doc(s);
  std::vector<uint8_t> good = write_doc(*src, AFM_PROFILE_RAW);
  const uint32_t xtra = AFM_FOURCC('X', 'T', 'R', 'A');
  DocPtr doc;
  afm_diag diag{};
  ASSERT_EQ(read(with_extra_chunk(good, xtra, 0, AFM_ENCODING_RAW), &doc, &diag), AFM_OK)
      << diag.message;
  EXPECT_EQ(doc->skipped_chunks, 1u);
  EXPECT_EQ(compare_docs(*src, *doc), "");
  diag = afm_diag{};
  EXPECT_EQ(read(with_extra_chunk(good, xtra, AFM_CHUNK_REQUIRED, AFM_ENCODING_RAW), &doc, &diag),
            AFM_ERR_UNKNOWN_REQUIRED);
  EXPECT_NE(std::string(diag.message).find("XTRA"), std::string::npos) << diag.message;
  // A known kind with an unknown encoding behaves the same way.
  EXPECT_EQ(read(with_extra_chunk(good, AFM_CHUNK_RIGD, AFM_CHUNK_REQUIRED, 7), &doc),
            AFM_ERR_UNKNOWN_REQUIRED);
  EXPECT_EQ(read(with_extra_chunk(good, AFM_CHUNK_GEOM, AFM_CHUNK_REQUIRED, AFM_ENCODING_RAW), &doc),
            AFM_ERR_DUPLICATE_CHUNK);
  // Transcoding keeps the unknown chunk.
  std::vector<uint8_t> extra = with_extra_chunk(good, xtra, 0, AFM_ENCODING_RAW);
  uint8_t *out = nullptr;
  size_t n = 0;
  ASSERT_EQ(afm_transcode(extra.data(), extra.size(), AFM_PROFILE_RAW, afm_draco_codec(), nullptr,
                          &out, &n, nullptr),
            AFM_OK);
  EXPECT_EQ(std::vector<uint8_t>(out, out + n), extra);
  afm_free(nullptr, out);
}

TEST(AfmFormat, WriterRefusesInvalidDocuments) {
  const SpoilCase cases[] = {
      {"triangle outside its part", [](SyntheticDoc &s) { s.tris[5] = s.parts[0].vertex_count + 3; },
       "outside the part"},
      {"repeated index", [](SyntheticDoc &s) { s.tris[1] = s.tris[0]; }, "repeated index"},
      {"duplicate target", [](SyntheticDoc &s) { s.targets[1].number = 3; s.targets[1].reference = 1024; },
       "appears twice"},  // the same FAP at the same reference (in-betweens differ in it)
      {"duplicate expression", [](SyntheticDoc &s) { s.targets[4] = s.targets[5]; },
       "appears twice"},
      {"run past the end",
       [](SyntheticDoc &s) { s.target_data[0].runs.back().start = s.doc.geometry.vertex_count - 1; },
       "passes vertex_count"},
      {"FDP vertex out of range", [](SyntheticDoc &s) { s.fdps[0].vertex = 1u << 30; }, "vertex"},
      {"bad FAP number", [](SyntheticDoc &s) { s.targets[0].number = 2; }, "not a valid target"},
      {"rigid part out of range", [](SyntheticDoc &s) { s.rigid_parts[0] = 9; }, "part_count"},
      {"zero reference", [](SyntheticDoc &s) { s.targets[2].reference = 0; }, "reference"},
      {"duplicate part name", [](SyntheticDoc &s) { s.parts[1].name = "skin"; }, "used twice"},
  };
  expect_writer_refuses(cases, sizeof cases / sizeof cases[0], afmtest::SyntheticOptions{});
}

// Damage inside Draco streams with valid CRCs: an error or a valid file,
// never a crash (run under ASan in CI).
TEST(AfmFormat, DamagedDracoStreamsFailCleanly) {
 for (bool lift : {false, true}) {
  SCOPED_TRACE(lift ? "with LIFT" : "without LIFT");
  SyntheticDoc s;
  afmtest::SyntheticOptions o;
  o.rows = 30, o.cols = 40;
  o.lift = lift;
  o.in_betweens = o.combination = !lift;  // a combination's gate in the MTGT headers
  std::vector<uint8_t> good = write_doc(*make_synthetic_doc(s, o), AFM_PROFILE_DRACO);
  afm_container c;
  ASSERT_EQ(afm_container_open(good.data(), good.size(), &c, nullptr), AFM_OK);
  std::mt19937 rng(1234);
  int errors = 0, trials = 0;
  for (uint32_t i = 0; i < c.chunk_count; ++i) {
    afm_chunk_info ch;
    afm_container_chunk(&c, i, &ch);
    if (ch.encoding != AFM_ENCODING_DRACO) continue;
    for (int t = 0; t < 150; ++t) {
      std::vector<uint8_t> bad = good;
      size_t at = ch.offset + rng() % ch.length;
      bad[at] ^= uint8_t(1 + rng() % 255);
      reseal_chunk(bad, i);
      DocPtr doc;
      if (read(bad, &doc) != AFM_OK) ++errors;
      ++trials;
    }
  }
  EXPECT_GT(trials, 0);
  EXPECT_GT(errors, trials / 4);  // most damage is caught, and none crashes
 }
}

// ---- control points (LIFT) -------------------------------------------------------

TEST(AfmFormat, LiftRoundTripsExactlyInBothProfiles) {
  SyntheticDoc s;
  afmtest::SyntheticOptions o;
  o.rows = 40, o.cols = 50;
  o.lift = true;
  const afm_doc *src = make_synthetic_doc(s, o);
  const std::vector<uint8_t> raw = write_doc(*src, AFM_PROFILE_RAW), draco = write_doc(*src, AFM_PROFILE_DRACO);
  EXPECT_EQ(chunk_encoding(raw, AFM_CHUNK_LIFT), AFM_ENCODING_RAW);
  EXPECT_EQ(chunk_encoding(draco, AFM_CHUNK_LIFT), AFM_ENCODING_DRACO);
  // A reader that does not know LIFT must refuse the file: the chunk is required.
  afm_container c;
  ASSERT_EQ(afm_container_open(raw.data(), raw.size(), &c, nullptr), AFM_OK);
  EXPECT_GE(c.minor, 1);  // 1.1 added LIFT
  for (uint32_t i = 0; i < c.chunk_count; ++i) {
    afm_chunk_info ch;
    afm_container_chunk(&c, i, &ch);
    if (ch.kind == AFM_CHUNK_LIFT) {
      EXPECT_TRUE(ch.flags & AFM_CHUNK_REQUIRED);
    }
  }
  for (const std::vector<uint8_t> *bytes : {&raw, &draco}) {
    DocPtr doc;
    afm_diag diag{};
    ASSERT_EQ(read(*bytes, &doc, &diag), AFM_OK) << diag.message;
    ASSERT_NE(doc->lift, nullptr);
    EXPECT_EQ(compare_docs(*src, *doc), "");
  }
  uint8_t *out = nullptr;
  size_t n = 0;
  ASSERT_EQ(afm_transcode(draco.data(), draco.size(), AFM_PROFILE_RAW, afm_draco_codec(), nullptr, &out, &n, nullptr),
            AFM_OK);
  EXPECT_EQ(std::vector<uint8_t>(out, out + n), raw);
  afm_free(nullptr, out);
  // Every prefix of a small lifted file is refused, in both profiles.
  o.rows = 8, o.cols = 10;
  SyntheticDoc small;
  const afm_doc *sd = make_synthetic_doc(small, o);
  for (afm_profile profile : {AFM_PROFILE_RAW, AFM_PROFILE_DRACO}) {
    const std::vector<uint8_t> bytes = write_doc(*sd, profile);
    for (size_t k = 0; k < bytes.size(); ++k) {
      DocPtr doc;
      ASSERT_NE(read(std::vector<uint8_t>(bytes.begin(), bytes.begin() + k), &doc), AFM_OK)
          << "prefix of " << k << " bytes accepted";
    }
  }
}

TEST(AfmFormat, LiftRulesAreEnforced) {
  afmtest::SyntheticOptions o;
  o.lift = true;
  {
    // The cases below assume the first target's first run is the eye's.
    SyntheticDoc s;
    make_synthetic_doc(s, o);
    ASSERT_GE(s.target_data[0].runs.size(), 1u);
    ASSERT_GE(s.target_data[0].runs[0].start, s.parts[1].first_vertex);
  }
  const SpoilCase cases[] = {
      {"control out of range", [](SyntheticDoc &s) { s.lift_c[2][5] = s.lift.control_count; }, "control"},
      {"weights above one", [](SyntheticDoc &s) { s.lift_w[0][9] = 20000, s.lift_w[1][9] = 20000; },
       "pass 32768"},
      {"no controls", [](SyntheticDoc &s) { s.lift.control_count = 0; }, "control_count is 0"},
      {"bound run past the vertices",
       [](SyntheticDoc &s) { s.lift_runs[0].start = s.doc.geometry.vertex_count - 10; }, "passes vertex_count"},
      {"bound count unlike the runs", [](SyntheticDoc &s) { s.lift.bound_count -= 1; }, "bound_count"},
      {"target over a bound vertex",
       [](SyntheticDoc &s) {
         // The eye's run of the first target moves down onto the last skin vertex.
         s.target_data[0].runs[0].start = s.parts[0].vertex_count - 1;
       },
       "bound to control points"},
      {"target run past the controls",
       [](SyntheticDoc &s) { s.target_data[1].runs.back().start = s.doc.geometry.vertex_count + s.lift.control_count - 1; },
       "passes vertex_count"},
      {"normal deltas with a lift",
       [](SyntheticDoc &s) {
         SyntheticDoc::Target &t = s.target_data[0];
         t.nx = t.ny = t.nz = t.dx;
         s.targets[0].flags = AFM_TARGET_NORMALS;
         s.targets[0].nx = t.nx.data(), s.targets[0].ny = t.ny.data(), s.targets[0].nz = t.nz.data();
       },
       "normal deltas"},
  };
  expect_writer_refuses(cases, sizeof cases / sizeof cases[0], o);
  // The reader applies the same rules to a file: a control index edited in
  // place, CRCs resealed.
  SyntheticDoc s;
  std::vector<uint8_t> f = write_doc(*make_synthetic_doc(s, o), AFM_PROFILE_RAW);
  ASSERT_TRUE(edit_chunk(f, AFM_CHUNK_LIFT, [&](const afm_chunk_info &ch) {
    const size_t c0 = ch.offset + 12 + 8 * size_t(s.lift.run_count);  // the first c0
    put32(&f[c0], s.lift.control_count + 7);
  }));
  DocPtr doc;
  afm_diag diag{};
  EXPECT_EQ(read(f, &doc, &diag), AFM_ERR_RANGE);
  EXPECT_EQ(diag.chunk, AFM_CHUNK_LIFT) << diag.message;
}

// A combination target (version 1.4) names a gate FAP other than its own
// and a gate reference, and follows a FAP target the file holds at its
// number and reference; its gate's padding is zero.
TEST(AfmFormat, CombinationRulesAreEnforced) {
  afmtest::SyntheticOptions o;
  o.in_betweens = o.combination = true;
  SyntheticDoc good;
  make_synthetic_doc(good, o);
  ASSERT_EQ(good.targets.back().kind, AFM_TARGET_COMBINATION);
  DocPtr doc;
  ASSERT_EQ(read(write_doc(good.doc, AFM_PROFILE_RAW), &doc), AFM_OK);
  EXPECT_EQ(compare_docs(good.doc, *doc), "");
  const SpoilCase cases[] = {
      {"gated by itself", [](SyntheticDoc &s) { s.targets.back().gate = 31; }, "gate FAP 31"},
      {"gate below FAP 3", [](SyntheticDoc &s) { s.targets.back().gate = 2; }, "gate FAP 2"},
      {"gate past FAP 68", [](SyntheticDoc &s) { s.targets.back().gate = 69; }, "gate FAP 69"},
      {"gate reference 0", [](SyntheticDoc &s) { s.targets.back().gate_reference = 0; }, "at 0"},
      {"no target at its reference", [](SyntheticDoc &s) { s.targets.back().reference = -701; },
       "no FAP target at that reference"},
      {"twice", [](SyntheticDoc &s) {
         s.targets.push_back(s.targets.back());
         s.doc.targets = s.targets.data();
         s.doc.target_count = uint32_t(s.targets.size());
       },
       "appears twice"},
  };
  expect_writer_refuses(cases, sizeof cases / sizeof cases[0], o);
  // The reader refuses the gate's padding not zero, CRCs resealed: the last
  // target's header ends with u8 gate, u8 0, u16 0, i32 gate_reference.
  SyntheticDoc s;
  std::vector<uint8_t> f = write_doc(*make_synthetic_doc(s, o), AFM_PROFILE_RAW);
  const afm_target &last = s.targets.back();
  const size_t tail = 8 * size_t(last.run_count) + 3 * ((2 * size_t(last.delta_count) + 3) / 4 * 4);
  ASSERT_TRUE(edit_chunk(f, AFM_CHUNK_MTGT, [&](const afm_chunk_info &ch) {
    const size_t gate = ch.offset + ch.length - tail - 8;  // the gate's first byte
    EXPECT_EQ(f[gate], 3) << "the last target's gate is not where expected";
    f[gate + 1] = 1;
  }));
  afm_diag diag{};
  EXPECT_EQ(read(f, &doc, &diag), AFM_ERR_RANGE);
  EXPECT_NE(std::string(diag.message).find("gate's reserved bytes not zero"), std::string::npos) << diag.message;
}

// afm_target_expand against the LIFT formula evaluated here on the synthetic
// document's own arrays (not through the reader): exact in Q15.
TEST(AfmFormat, TargetExpandLiftsControlsExactly) {
  for (bool lift : {false, true}) {
    SyntheticDoc s;
    afmtest::SyntheticOptions o;
    o.lift = lift;
    const afm_doc *src = make_synthetic_doc(s, o);
    DocPtr doc;
    ASSERT_EQ(read(write_doc(*src, AFM_PROFILE_DRACO), &doc), AFM_OK);
    const size_t V = src->geometry.vertex_count, E = size_t(afm_doc_entry_count(doc.get()));
    EXPECT_EQ(E, V + (lift ? s.lift.control_count : 0));
    size_t bound_moved = 0;
    for (uint32_t t = 0; t < src->target_count; ++t) {
      // Dense deltas of every entry from the synthetic target's runs.
      std::vector<int64_t> dense(3 * E, 0);
      const SyntheticDoc::Target &st = s.target_data[t];
      size_t k = 0;
      for (const afm_run &r : st.runs)
        for (uint32_t j = 0; j < r.length; ++j, ++k) {
          dense[3 * (r.start + j)] = st.dx[k], dense[3 * (r.start + j) + 1] = st.dy[k];
          dense[3 * (r.start + j) + 2] = st.dz[k];
        }
      std::vector<int64_t> want(3 * V);
      for (size_t v = 0; v < 3 * V; ++v) want[v] = 32768 * dense[v];
      if (lift)
        for (uint32_t b = 0; b < s.lift.bound_count; ++b) {  // one run: bound vertex b is vertex b
          const int64_t w[3] = {32768 - s.lift_w[0][b] - s.lift_w[1][b], s.lift_w[0][b], s.lift_w[1][b]};
          for (int c = 0; c < 3; ++c) {
            want[3 * b + size_t(c)] = 0;
            for (int i = 0; i < 3; ++i) want[3 * b + size_t(c)] += w[i] * dense[3 * (V + s.lift_c[i][b]) + size_t(c)];
          }
          bound_moved += want[3 * b] || want[3 * b + 1] || want[3 * b + 2];
        }
      std::vector<int32_t> got(3 * E);
      ASSERT_EQ(afm_target_expand(doc.get(), &doc->targets[t], got.data()), AFM_OK);
      for (size_t v = 0; v < 3 * V; ++v) ASSERT_EQ(got[v], want[v]) << "target " << t << " value " << v;
    }
    if (lift) {
      EXPECT_GT(bound_moved, 100u);  // the lift is exercised
    }
  }
}

TEST(AfmFormat, Crc32MatchesTheStandardCheckValue) {
  const char *check = "123456789";  // CRC-32/ISO-HDLC check value
  EXPECT_EQ(afm_crc32(reinterpret_cast<const uint8_t *>(check), 9), 0xCBF43926u);
  EXPECT_EQ(afm_crc32(nullptr, 0), 0u);
}
