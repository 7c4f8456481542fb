// Where tests find files: the project's own tree and ../shared beside it.
#pragma once

#include <gtest/gtest.h>

#include <string>

namespace afmtest {

// Root of the project checkout.
std::string source_dir();
// ../shared/data (or $AFM_SHARED_DIR/data); empty when absent.
std::string shared_data_dir();
// Full path of a file under ../shared/data, or empty when the data is absent.
std::string shared_data(const std::string &relative);
// ../shared/reference (or $AFM_SHARED_DIR/reference); empty when absent.
std::string shared_reference_dir();
// Full path of a file under ../shared/reference, or empty when it is absent.
std::string shared_reference(const std::string &relative);
// A fresh, empty directory for this test's outputs.
std::string temp_dir(const std::string &name);
// Reads a whole file; empty when unreadable.
std::string read_file(const std::string &path);

}  // namespace afmtest

// Skips the current test with a clear message when ../shared/data is absent.
#define AFM_REQUIRE_SHARED_DATA()                                              \
  do {                                                                         \
    if (afmtest::shared_data_dir().empty())                                    \
      GTEST_SKIP() << "../shared/data is absent: this test needs the shared "  \
                      "data files (set AFM_SHARED_DIR to point elsewhere)";    \
  } while (0)

// Skips the current test when ../shared/reference is absent.
#define AFM_REQUIRE_SHARED_REFERENCE()                                         \
  do {                                                                         \
    if (afmtest::shared_reference_dir().empty())                               \
      GTEST_SKIP() << "../shared/reference is absent: this test needs the "    \
                      "reference tables (set AFM_SHARED_DIR to point "         \
                      "elsewhere)";                                            \
  } while (0)
