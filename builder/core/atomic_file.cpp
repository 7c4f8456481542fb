#include "core/atomic_file.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

namespace afmb {

namespace {

std::string temporary_beside(const std::string &path) {
  return path + ".tmp." + std::to_string(static_cast<long>(getpid()));
}

// Creates and removes `probe`; the error is about `named`.
Status probe_file(const std::string &probe, const std::string &named, const char *what) {
  FILE *f = std::fopen(probe.c_str(), "wb");
  if (!f) return Status::error(named + ": " + what + ": " + std::strerror(errno));
  std::fclose(f);
  std::remove(probe.c_str());
  return Status::ok();
}

}  // namespace

Status write_file_atomic(const std::string &path, const void *data, size_t size) {
  // Same directory as the target, so rename() never crosses file systems.
  const std::string tmp = temporary_beside(path);
  FILE *f = std::fopen(tmp.c_str(), "wb");
  if (!f) return Status::error(path + ": cannot create: " + std::strerror(errno));
  bool ok = size == 0 || std::fwrite(data, 1, size, f) == size;
  ok = (std::fflush(f) == 0) && ok;
  ok = (std::fclose(f) == 0) && ok;
  if (!ok) {
    int e = errno;
    std::remove(tmp.c_str());
    return Status::error(path + ": write failed: " + std::strerror(e));
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    int e = errno;
    std::remove(tmp.c_str());
    return Status::error(path + ": cannot rename into place: " + std::strerror(e));
  }
  return Status::ok();
}

Status write_file_atomic(const std::string &path, std::string_view text) {
  return write_file_atomic(path, text.data(), text.size());
}

Status check_writable(const std::string &path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return Status::error(path + ": cannot create: it is a directory");
  return probe_file(temporary_beside(path), path, "cannot create");
}

Status check_fillable_directory(const std::string &dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::path at = fs::path(dir);
  if (fs::exists(at, ec) && !fs::is_directory(at, ec)) return Status::error(dir + ": not a directory");
  // The nearest existing ancestor ("." for a relative path's first part).
  while (!at.empty() && !fs::exists(at, ec)) at = at.parent_path();
  if (at.empty()) at = ".";
  if (!fs::is_directory(at, ec))
    return Status::error(dir + ": cannot make the directory: " + at.string() + " is not a directory");
  const std::string probe = (at / (".afm-probe." + std::to_string(static_cast<long>(getpid())))).string();
  return probe_file(probe, dir, at == fs::path(dir) ? "cannot write into it" : "cannot make the directory");
}

Expected<std::string> read_file(const std::string &path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::error(path + ": cannot open: " + std::strerror(errno));
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) return Status::error(path + ": read failed");
  return ss.str();
}

}  // namespace afmb
