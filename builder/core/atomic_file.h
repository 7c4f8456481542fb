// Files that appear complete or not at all.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include "core/status.h"

namespace afmb {

// Writes to a temporary file beside `path`, then renames it over `path`. On
// any failure the temporary is removed and `path` is left as it was.
Status write_file_atomic(const std::string &path, const void *data, size_t size);
Status write_file_atomic(const std::string &path, std::string_view text);

// Checks, before long work, that write_file_atomic(path, ...) will be able
// to write: `path` is not a directory, and the temporary it writes beside
// `path` can be created (it is created and removed again; `path` itself is
// not touched). The error names the path and the system's reason, as
// write_file_atomic's would.
Status check_writable(const std::string &path);

// The same for a directory that work will fill with files, made with its
// missing parents (std::filesystem::create_directories): an existing `dir`
// must be a directory that takes a new file; a missing one needs its
// nearest existing ancestor to be a directory that does. Nothing is left
// behind.
Status check_fillable_directory(const std::string &dir);

// Reads a whole file. The error names the path and the system's reason.
Expected<std::string> read_file(const std::string &path);

}  // namespace afmb
