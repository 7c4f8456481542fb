// A small CSV reader for the reference tables in ../shared/reference.
//
// RFC 4180 style: comma-separated fields, fields in double quotes may hold
// commas and doubled quotes (""), LF or CRLF line ends. The first row names
// the columns. Tests use it to compare code against the reference files.
#pragma once

#include <map>
#include <string>
#include <vector>

namespace afmtest {

struct CsvTable {
  std::vector<std::string> columns;
  std::vector<std::map<std::string, std::string>> rows;  // column name -> field
  std::string error;  // non-empty when the file could not be read or parsed
};

CsvTable read_csv(const std::string &path);

// Splits `text` at `sep`, keeping empty pieces ("a;;b" -> "a", "", "b").
std::vector<std::string> split(const std::string &text, char sep);

}  // namespace afmtest
