// The small XML reader behind the XfaceEd FDP files.
#include "io/xml.h"

#include <gtest/gtest.h>

#include <string>

namespace {

using afmb::parse_xml;
using afmb::XmlElement;

TEST(Xml, ReadsElementsAttributesTextAndLines) {
  const char *doc =
      "\xEF\xBB\xBF<?xml version=\"1.0\" standalone='yes' ?>\n"
      "<!-- a comment -->\n"
      "<root a=\"1\" b = 'two words'>\n"
      "  <child x=\"&lt;&amp;&gt;&quot;&apos;&#65;&#x42;&#xE9;\"/>\n"
      "  <!-- inside -->\n"
      "  <?pi ignored?>\n"
      "  <list>1 2\n3</list><empty></empty>\n"
      "  <cdata><![CDATA[<not markup> & stuff]]></cdata>\n"
      "</root>\n"
      "<!-- trailing comment -->\n";
  auto r = parse_xml(doc, "t.xml");
  ASSERT_TRUE(r) << r.status().message();
  const XmlElement &root = *r;
  EXPECT_EQ(root.name, "root");
  EXPECT_EQ(root.line, 3);
  ASSERT_EQ(root.attributes.size(), 2u);
  EXPECT_EQ(root.attribute("a")->value, "1");
  EXPECT_EQ(root.attribute("b")->value, "two words");
  EXPECT_EQ(root.attribute("b")->line, 3);
  EXPECT_EQ(root.attribute("c"), nullptr);
  ASSERT_EQ(root.children.size(), 4u);
  EXPECT_EQ(root.children[0].name, "child");
  EXPECT_EQ(root.children[0].line, 4);
  EXPECT_EQ(root.children[0].attribute("x")->value, "<&>\"'AB\xC3\xA9");
  EXPECT_EQ(root.child("list")->text, "1 2\n3");
  EXPECT_EQ(root.child("list")->line, 7);
  EXPECT_EQ(root.child("empty")->text, "");
  EXPECT_EQ(root.child("cdata")->text, "<not markup> & stuff");
  EXPECT_EQ(root.child("cdata")->line, 9);
  EXPECT_EQ(root.child("nope"), nullptr);
}

TEST(Xml, AttributeValuesNormaliseBlanks) {
  auto r = parse_xml("<a v=\"x\ty\nz\"/>", "t.xml");
  ASSERT_TRUE(r) << r.status().message();
  EXPECT_EQ(r->attribute("v")->value, "x y z");
}

struct Bad {
  const char *text;
  const char *expect;  // substring of the message, which also names t.xml:<line>
  int line;
};

TEST(Xml, RejectsMalformedDocumentsNamingTheLine) {
  const Bad cases[] = {
      {"<a>\n<b>\n</a>", "</a> closes <b> opened at line 2", 3},
      {"<a>\n<b>", "end of file inside <b> opened at line 2", 2},
      {"<a x=\"1\" x=\"2\"/>", "duplicate attribute 'x'", 1},
      {"<a x=1/>", "not quoted", 1},
      {"<a x/>", "has no '='", 1},
      {"<a x=\"1\"y=\"2\"/>", "not separated by a blank", 1},
      {"<a x=\"<\"/>", "'<' in the value", 1},
      {"<a>\n&nbsp;</a>", "unknown entity &nbsp;", 2},
      {"<a>AT&T</a>", "does not start an entity", 1},
      {"<a>&#0;</a>", "is not a character", 1},
      {"<a x=\"1\n", "unterminated value of attribute 'x'", 1},
      {"<a/>\n<b/>", "a second element after the root element <a>", 2},
      {"<a/>\ntext", "text after the root element <a>", 2},
      {"text <a/>", "text before the root element", 1},
      {"<!DOCTYPE a>\n<a/>", "DOCTYPE", 1},
      {"\n\n<!-- open", "unterminated comment", 3},
      {"<a/>\n<?xml version=\"1.0\"?>", "XML declaration not at the start", 2},
      {"", "no root element", 1},
      {"<a>\n<1/></a>", "expected an element name after '<'", 2},
      {"<a>\n</a", "end tag </a> has no '>'", 2},
      {"<a><![CDATA[x</a>", "unterminated CDATA", 1},
  };
  for (const Bad &b : cases) {
    auto r = parse_xml(b.text, "t.xml");
    ASSERT_FALSE(r) << b.text;
    const std::string &m = r.status().message();
    EXPECT_NE(m.find(b.expect), std::string::npos) << b.text << " -> " << m;
    EXPECT_EQ(m.rfind("t.xml:" + std::to_string(b.line) + ": ", 0), 0u) << b.text << " -> " << m;
  }
}

TEST(Xml, BoundsTheNestingDepth) {
  std::string deep;
  for (int i = 0; i < 300; ++i) deep += "<a>";
  auto r = parse_xml(deep, "deep.xml");
  ASSERT_FALSE(r);
  EXPECT_NE(r.status().message().find("nested deeper than 256"), std::string::npos) << r.status().message();
  std::string ok;
  for (int i = 0; i < 200; ++i) ok += "<a>";
  for (int i = 0; i < 200; ++i) ok += "</a>";
  EXPECT_TRUE(parse_xml(ok, "ok.xml"));
}

}  // namespace
