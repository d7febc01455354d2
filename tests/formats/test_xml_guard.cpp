// The XML text libcitygml is given (src/formats/xml_guard.cpp, internal to formats): document
// types and wide or unknown encodings refused in one line, ISO-8859-1 made UTF-8, nesting bounded,
// character data Xerces would split into pieces handed over whole as one CDATA section.
#include <gtest/gtest.h>

#include <string>

#include "formats/xml_guard.h"
#include "lodrefine/base/types.h"

using namespace lodrefine;
using io_xml::kMaxElementDepth;
using io_xml::safe_citygml_text;

namespace {

// The refusal's one line, or "accepted".
std::string refusal(const std::string& text) {
  try {
    safe_citygml_text(text, "city.gml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "accepted";
}

std::string nested(int depth) {
  std::string t = "<?xml version=\"1.0\"?>";
  for (int i = 0; i < depth; ++i) t += "<a x=\"1>2\">";
  for (int i = 0; i < depth; ++i) t += "</a>";
  return t;
}

}  // namespace

TEST(XmlGuard, PlainUtf8IsHandedOverAsItIs) {
  const std::string doc = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<c><n a=\"&amp;\">Delft</n><!-- c --></c>\n";
  EXPECT_EQ(safe_citygml_text(doc, "city.gml"), doc);
}

TEST(XmlGuard, TextInPiecesBecomesOneCdataSection) {
  EXPECT_EQ(safe_citygml_text("<n>Bakery &amp; Sons</n>", "city.gml"), "<n><![CDATA[Bakery & Sons]]></n>");
  EXPECT_EQ(safe_citygml_text("<n>&#65;&#x42;C</n>", "city.gml"), "<n><![CDATA[ABC]]></n>");
  // An unknown entity is left for Xerces to refuse.
  EXPECT_EQ(safe_citygml_text("<n>a &nope; b</n>", "city.gml"), "<n>a &nope; b</n>");
}

TEST(XmlGuard, DeclarationsOtherThanCommentsAndCdataAreRefused) {
  const std::string doctype =
      refusal("<?xml version=\"1.0\"?><!DOCTYPE c [<!ENTITY e SYSTEM \"/etc/passwd\">]><c>&e;</c>");
  EXPECT_EQ(doctype.rfind("city.gml: the XML has a document type or entity declaration ('<!DOCTYPE", 0), 0u) << doctype;
  EXPECT_EQ(doctype.find('\n'), std::string::npos);
  EXPECT_EQ(refusal("<c><![CDATA[<!DOCTYPE x>]]></c>"), "accepted");
}

TEST(XmlGuard, WideAndUnknownEncodingsAreRefused) {
  EXPECT_NE(refusal("\xFF\xFE<\0c\0>\0").find("UTF-16 or UTF-32"), std::string::npos);
  EXPECT_NE(refusal(std::string("<\0\0\0", 4)).find("UTF-16 or UTF-32"), std::string::npos);
  EXPECT_EQ(refusal("<?xml version=\"1.0\" encoding=\"EBCDIC-CP-US\"?><c/>"),
            "city.gml: XML encoding 'ebcdic-cp-us' is not read (UTF-8, US-ASCII or ISO-8859-1)");
  EXPECT_EQ(refusal("<?xml version=\"1.0\" encoding='us-ascii'?><c/>"), "accepted");
}

TEST(XmlGuard, Latin1IsTranscodedAndSaysSo) {
  const std::string out =
      safe_citygml_text("<?xml version=\"1.0\" encoding=\"ISO-8859-1\"?><n>Caf\xE9</n>", "city.gml");
  EXPECT_EQ(out, "<?xml version=\"1.0\" encoding=\"UTF-8\"?><n>Caf\xC3\xA9</n>");
}

TEST(XmlGuard, NestingIsBoundedAtItsLimit) {
  EXPECT_EQ(kMaxElementDepth, 256);
  EXPECT_EQ(refusal(nested(kMaxElementDepth)), "accepted");
  EXPECT_EQ(refusal(nested(kMaxElementDepth + 1)),
            "city.gml: the XML nests elements more than 256 deep: not accepted, CityGML needs a few dozen levels");
  // Self-closing tags and stray end tags bank no levels.
  std::string flat = "<c>";
  for (int i = 0; i < 1000; ++i) flat += "<e/></x>";
  EXPECT_EQ(refusal(flat + "</c>"), "accepted");
}
