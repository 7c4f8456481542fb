// A small, strict XML reader for the project's XML inputs (XfaceEd .fdp).
//
// Reads one document into a tree of elements. Takes: an optional UTF-8 byte
// order mark, the <?xml ...?> declaration, other processing instructions
// (skipped), comments (skipped), elements with attributes quoted by ' or ",
// empty elements (<a/>), character data with the five predefined entities
// and numeric character references (&#65; &#x41;), and CDATA sections.
// Rejects, naming the line: DOCTYPE (and so any user-defined entity), a
// mismatched or missing end tag, a duplicate attribute, an unquoted value,
// '<' in an attribute value, an unknown entity, text or a second element
// after the root, and nesting deeper than 256 elements.
// No namespaces (a prefix stays part of the name), no encodings other than
// UTF-8 / ASCII (bytes are passed through), no validation.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "core/status.h"

namespace afmb {

struct XmlAttribute {
  std::string name;
  std::string value;  // entities decoded
  int line = 0;       // 1-based line of the attribute's name
};

struct XmlElement {
  std::string name;
  std::vector<XmlAttribute> attributes;  // in document order, names unique
  std::vector<XmlElement> children;      // child elements in document order
  std::string text;  // character data directly inside, pieces concatenated, decoded
  int line = 0;      // 1-based line of the '<' that opens the element

  // The attribute called `name`, or nullptr.
  const XmlAttribute *attribute(std::string_view name) const;
  // The first child element called `name`, or nullptr.
  const XmlElement *child(std::string_view name) const;
};

// Parses a whole document and returns its root element. `source_name` starts
// every error message: "alice.fdp:12: </fdp> closes <influence> opened at
// line 11".
Expected<XmlElement> parse_xml(std::string_view text, const std::string &source_name);

}  // namespace afmb
