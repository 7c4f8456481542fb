// ASCII FAP parse speed (afm/fap_stream.h), in MB/s on one core.
//
// Streams:
//   real-int   the xface files (integer values), their frames repeated and
//              renumbered into one stream of about 4 MB;
//   real-dec   the same from the crystal files (decimal values, comments);
//   synthetic  a generated stream of the same shape: 68-entry masks with about
//              45 FAPs set, integer values, and one frame in four in decimals.
// Each is read whole (afm_fap_parse into a frame array) and fed in 4 KB
// chunks (afm_fap_reader_feed). Best of several runs of at least 0.3 s.
// The real streams need ../shared/data; without it only the synthetic one runs.
#include <afm/fap_stream.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

constexpr double kGoalMBs = 50.0;
constexpr size_t kTargetBytes = 4u << 20;

std::string shared_data_dir() {
  fs::path shared;
  if (const char *s = std::getenv("AFM_SHARED_DIR"))
    shared = s;
  else
    shared = fs::path(AFM_SOURCE_DIR) / ".." / "shared";
  std::error_code ec;
  fs::path d = shared / "data";
  return fs::is_directory(d, ec) ? d.string() : std::string();
}

std::string read_file(const fs::path &p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// The frames of a .fap text as (comment lines, mask line, value line without
// its frame number), by layout alone: the header is the first line that is
// not a comment; then mask and value lines alternate.
struct TextFrame {
  std::string comments, mask, values;
};

std::vector<TextFrame> split_frames(const std::string &text) {
  std::vector<TextFrame> out;
  std::istringstream in(text);
  std::string line, comments;
  bool header = true, want_mask = true;
  TextFrame f;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    size_t first = line.find_first_not_of(" \t");
    if (first == std::string::npos) continue;
    if (line[first] == '#') {
      comments += line + "\n";
      continue;
    }
    if (header) {
      header = false;
      continue;
    }
    if (want_mask) {
      f.comments = comments;
      comments.clear();
      f.mask = line;
    } else {
      size_t sp = line.find_first_of(" \t", first);
      f.values = sp == std::string::npos ? std::string() : line.substr(sp);
      out.push_back(f);
    }
    want_mask = !want_mask;
  }
  return out;
}

// Repeats `frames` (renumbered from 0) to about kTargetBytes.
std::string repeat_stream(const std::vector<TextFrame> &frames, uint32_t *count) {
  std::string body;
  uint32_t n = 0;
  while (body.size() < kTargetBytes && !frames.empty())
    for (const TextFrame &f : frames) {
      body += f.comments;
      body += f.mask;
      body += '\n';
      body += std::to_string(n++);
      body += f.values;
      body += '\n';
    }
  *count = n;
  return "2.1 bench 25 " + std::to_string(n) + "\n" + body;
}

std::string synthetic_stream(uint32_t *count) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> bit(0, 99), val(-400, 400), frac(0, 99999);
  std::string s;
  uint32_t n = 0;
  std::string body;
  while (body.size() < kTargetBytes) {
    std::string mask, values = std::to_string(n);
    bool decimals = n % 4 == 3;
    for (int f = 1; f <= 68; ++f) {
      bool on = f >= 3 && bit(rng) < 66;  // about 45 of 66
      mask += on ? "1 " : "0 ";
      if (!on) continue;
      values += ' ';
      values += std::to_string(val(rng));
      if (decimals) {
        char buf[16];
        std::snprintf(buf, sizeof buf, ".%05d", frac(rng));
        values += buf;
      }
    }
    body += mask + "\n" + values + "\n";
    ++n;
  }
  *count = n;
  return "2.1 synthetic 25 " + std::to_string(n) + "\n" + body;
}

// Runs fn until 0.3 s have passed; best seconds per run of 5 such rounds.
template <class Fn>
double best_seconds(Fn fn) {
  double best = 1e30;
  for (int round = 0; round < 5; ++round) {
    int runs = 0;
    auto t0 = Clock::now();
    double elapsed = 0;
    do {
      fn();
      ++runs;
      elapsed = std::chrono::duration<double>(Clock::now() - t0).count();
    } while (elapsed < 0.3);
    best = std::min(best, elapsed / runs);
  }
  return best;
}

[[noreturn]] void die(const char *what, afm_result r, const afm_diag &d) {
  std::fprintf(stderr, "bench_fap: %s: %s: %s\n", what, afm_result_string(r), d.message);
  std::exit(1);
}

struct Result {
  double whole, chunked;
};

Result bench(const char *name, const std::string &text, uint32_t expected) {
  const uint8_t *data = reinterpret_cast<const uint8_t *>(text.data());
  std::vector<afm_fap_frame> frames(expected);
  afm_diag diag{};
  uint32_t count = 0;
  afm_result r = afm_fap_parse(data, text.size(), nullptr, frames.data(), expected, &count,
                               nullptr, nullptr, &diag);
  if (r != AFM_OK || count != expected) die(name, r, diag);

  double whole = best_seconds([&] {
    uint32_t c = 0;
    afm_fap_parse(data, text.size(), nullptr, frames.data(), expected, &c, nullptr, nullptr,
                  nullptr);
  });

  auto reader = std::make_unique<afm_fap_reader>();
  double chunked = best_seconds([&] {
    afm_fap_reader_init(reader.get(), nullptr, nullptr);
    afm_fap_frame frame;
    uint32_t got = 0;
    for (size_t at = 0; at < text.size();) {
      size_t end = std::min(text.size(), at + 4096);
      while (at < end) {
        size_t used = 0;
        int has = 0;
        afm_result res = afm_fap_reader_feed(reader.get(), data + at, end - at, &used, &frame, &has);
        if (res != AFM_OK) die(name, res, diag);
        at += used;
        got += static_cast<uint32_t>(has);
      }
    }
    int has = 0;
    if (afm_fap_reader_finish(reader.get(), &frame, &has) != AFM_OK || got != expected)
      die(name, AFM_ERR_STATE, diag);
  });

  const double mb = static_cast<double>(text.size()) / 1e6;
  std::printf("%-10s %6.2f MB %7u frames   whole %7.1f MB/s   4 KB chunks %7.1f MB/s\n", name,
              mb, expected, mb / whole, mb / chunked);
  return {mb / whole, mb / chunked};
}

}  // namespace

int main() {
  std::printf("ASCII FAP parse speed, one core (goal >= %.0f MB/s)\n", kGoalMBs);
  double worst = 1e30;
  std::string dir = shared_data_dir();
  if (dir.empty()) {
    std::printf("../shared/data absent: real-file streams skipped\n");
  } else {
    for (const char *family : {"xface", "crystal"}) {
      std::vector<fs::path> files;
      for (const auto &e : fs::directory_iterator(fs::path(dir) / "fap" / family))
        if (e.path().extension() == ".fap") files.push_back(e.path());
      std::sort(files.begin(), files.end());
      std::vector<TextFrame> frames;
      for (const auto &p : files) {
        auto f = split_frames(read_file(p));
        frames.insert(frames.end(), f.begin(), f.end());
      }
      uint32_t n = 0;
      std::string text = repeat_stream(frames, &n);
      Result r = bench(family[0] == 'x' ? "real-int" : "real-dec", text, n);
      worst = std::min({worst, r.whole, r.chunked});
    }
  }
  uint32_t n = 0;
  std::string text = synthetic_stream(&n);
  Result r = bench("synthetic", text, n);
  worst = std::min({worst, r.whole, r.chunked});
  std::printf("slowest: %.1f MB/s; goal >= %.0f MB/s: %s\n", worst, kGoalMBs,
              worst >= kGoalMBs ? "met" : "NOT met");
  return 0;
}
