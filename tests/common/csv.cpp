#include "csv.h"

#include "test_paths.h"

namespace afmtest {

namespace {
// Splits one CSV text into records of fields; false on an unterminated quote.
bool parse_records(const std::string &text, std::vector<std::vector<std::string>> *out) {
  std::vector<std::string> record;
  std::string field;
  bool quoted = false, any = false;
  for (size_t i = 0; i < text.size(); ++i) {
    char c = text[i];
    if (quoted) {
      if (c == '"') {
        if (i + 1 < text.size() && text[i + 1] == '"') {
          field += '"';
          ++i;
        } else {
          quoted = false;
        }
      } else {
        field += c;
      }
      continue;
    }
    if (c == '"') {
      quoted = true;
      any = true;
    } else if (c == ',') {
      record.push_back(field);
      field.clear();
      any = true;
    } else if (c == '\r' && i + 1 < text.size() && text[i + 1] == '\n') {
      // CRLF: the '\n' ends the record.
    } else if (c == '\n') {
      record.push_back(field);
      out->push_back(record);
      record.clear();
      field.clear();
      any = false;
    } else {
      field += c;
      any = true;
    }
  }
  if (quoted) return false;
  if (any) {
    record.push_back(field);
    out->push_back(record);
  }
  return true;
}
}  // namespace

CsvTable read_csv(const std::string &path) {
  CsvTable t;
  std::string text = read_file(path);
  if (text.empty()) {
    t.error = path + ": empty or unreadable";
    return t;
  }
  std::vector<std::vector<std::string>> records;
  if (!parse_records(text, &records)) {
    t.error = path + ": unterminated quoted field";
    return t;
  }
  if (records.empty()) {
    t.error = path + ": no header row";
    return t;
  }
  t.columns = records[0];
  for (size_t r = 1; r < records.size(); ++r) {
    if (records[r].size() != t.columns.size()) {
      t.error = path + ": record " + std::to_string(r + 1) + " has " +
                std::to_string(records[r].size()) + " fields, the header " +
                std::to_string(t.columns.size());
      return t;
    }
    std::map<std::string, std::string> row;
    for (size_t c = 0; c < t.columns.size(); ++c) row[t.columns[c]] = records[r][c];
    t.rows.push_back(std::move(row));
  }
  return t;
}

std::vector<std::string> split(const std::string &text, char sep) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : text) {
    if (c == sep) {
      out.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  out.push_back(cur);
  return out;
}

}  // namespace afmtest
