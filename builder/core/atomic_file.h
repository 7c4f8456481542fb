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

// Reads a whole file. The error names the path and the system's reason.
Expected<std::string> read_file(const std::string &path);

}  // namespace afmb
