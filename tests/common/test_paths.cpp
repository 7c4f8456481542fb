#include "test_paths.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace fs = std::filesystem;

namespace afmtest {

std::string source_dir() {
  if (const char *s = std::getenv("AFM_SOURCE_DIR")) return s;
  return AFM_SOURCE_DIR;
}

namespace {
// ../shared/<name> (or $AFM_SHARED_DIR/<name>) when it is a directory, else "".
std::string shared_subdir(const char *name) {
  fs::path shared;
  if (const char *s = std::getenv("AFM_SHARED_DIR"))
    shared = s;
  else
    shared = fs::path(source_dir()) / ".." / "shared";
  fs::path dir = shared / name;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return {};
  return dir.lexically_normal().string();
}
}  // namespace

std::string shared_data_dir() { return shared_subdir("data"); }

std::string shared_reference_dir() { return shared_subdir("reference"); }

std::string shared_reference(const std::string &relative) {
  std::string d = shared_reference_dir();
  if (d.empty()) return {};
  return (fs::path(d) / relative).string();
}

std::string shared_data(const std::string &relative) {
  std::string d = shared_data_dir();
  if (d.empty()) return {};
  return (fs::path(d) / relative).string();
}

std::string temp_dir(const std::string &name) {
  const char *b = std::getenv("AFM_BUILD");
  fs::path root = fs::path(source_dir()) / (b ? b : "build") / "test-output" / name;
  std::error_code ec;
  fs::remove_all(root, ec);
  fs::create_directories(root);
  return root.string();
}

std::string read_file(const std::string &path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace afmtest
