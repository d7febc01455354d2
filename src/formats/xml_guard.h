// Internal to the formats library: the XML text libcitygml is given. libcitygml builds its Xerces-C
// parser itself and offers no hook for entity resolution, DTD loading or its SAX handler, so
// what it must not see is taken out here, before it parses anything.
#pragma once
#include <string>

namespace lodrefine::io_xml {

// The XML document `text` (read from `path`, named in errors) as UTF-8 that is safe to give
// libcitygml:
//  - refused (InputError "<path>: ...", one line) when it holds a document type declaration
//    (<!DOCTYPE ...>, where entities and external DTDs live: file disclosure, URL fetches,
//    billion laughs), or any other `<!` declaration than a comment or CDATA section; when it
//    is UTF-16/UTF-32 (byte order mark or NUL bytes in the first characters) or declares an
//    encoding other than UTF-8, US-ASCII or ISO-8859-1 (the check above reads bytes as ASCII);
//    when its elements nest more than kMaxElementDepth deep (libcitygml and the reader walk
//    nested objects and geometries recursively: 20,000 nested BuildingParts overflowed the
//    stack; real CityGML nests ~15 levels, a few dozen with openings and ADEs);
//  - ISO-8859-1 is transcoded to UTF-8 (and its declaration says so);
//  - character data between two tags that Xerces would deliver in pieces (at every entity or
//    character reference, at a CDATA section beside text) is decoded and written as one CDATA
//    section: libcitygml keeps only the last piece ("Bakery &amp; Sons" arrived as "& Sons").
//    Text with an unknown entity is left for Xerces to refuse.
// Attribute values inside tags are left as they are (Xerces hands those over whole).
std::string safe_citygml_text(std::string text, const std::string& path);
inline constexpr int kMaxElementDepth = 256;

}  // namespace lodrefine::io_xml
