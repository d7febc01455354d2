// The XML text libcitygml is given (see xml_guard.h).
#include "xml_guard.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <optional>
#include <string_view>

#include "lodrefine/base/text.h"

namespace lodrefine::io_xml {
namespace {

constexpr auto npos = std::string_view::npos;

bool starts_with(std::string_view s, std::size_t at, std::string_view prefix) {
  return s.compare(at, prefix.size(), prefix) == 0;
}

// UTF-16 and UTF-32, with or without a byte order mark: a BOM other than UTF-8's, or a NUL
// among the first four bytes (an XML document starts with '<' or whitespace).
void refuse_wide_encodings(std::string_view t, const std::string& path) {
  if (starts_with(t, 0, "\xFE\xFF") || starts_with(t, 0, "\xFF\xFE") || t.substr(0, 4).find('\0') != npos)
    io_text::fail(path, "XML in UTF-16 or UTF-32 is not read (save the file as UTF-8)");
}

// Where the XML declaration's encoding name sits (length 0 when there is none).
struct Span {
  std::size_t pos = 0, len = 0;
};

Span declared_encoding(std::string_view t, std::size_t start) {
  if (!starts_with(t, start, "<?xml")) return {};
  const auto end = t.find("?>", start);
  const auto key = t.find("encoding", start);
  if (end == npos || key == npos || key > end) return {};
  const auto open = t.find_first_of("\"'", key);
  if (open == npos || open > end) return {};
  const auto close = t.find(t[open], open + 1);
  if (close == npos || close > end) return {};
  return {open + 1, close - open - 1};
}

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = char(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

std::string latin1_to_utf8(std::string_view t) {
  std::string out;
  out.reserve(t.size());
  for (const char ch : t) {
    const auto c = static_cast<unsigned char>(ch);
    if (c < 0x80) {
      out += ch;
    } else {
      out += char(0xC0 | (c >> 6));
      out += char(0x80 | (c & 0x3F));
    }
  }
  return out;
}

// The text as UTF-8: UTF-8 and US-ASCII as they are, ISO-8859-1 transcoded (its declaration
// then says UTF-8); every other declared encoding refused, since the markup checks read bytes.
std::string as_utf8(std::string text, const std::string& path) {
  refuse_wide_encodings(text, path);
  const std::size_t start = starts_with(text, 0, "\xEF\xBB\xBF") ? 3 : 0;
  const Span enc = declared_encoding(text, start);
  const std::string name = lower(std::string_view(text).substr(enc.pos, enc.len));
  if (enc.len == 0 || name == "utf-8" || name == "utf8" || name == "us-ascii" || name == "ascii") return text;
  if (name == "iso-8859-1" || name == "iso_8859-1" || name == "latin1" || name == "latin-1") {
    text.replace(enc.pos, enc.len, "UTF-8");
    return latin1_to_utf8(text);
  }
  io_text::fail(path, "XML encoding " + io_text::quote(name) + " is not read (UTF-8, US-ASCII or ISO-8859-1)");
}

// An XML 1.0 Char other than CR (CDATA would read a CR as a line end and make it LF).
bool allowed_char(unsigned long c) {
  return c == 0x9 || c == 0xA || (c >= 0x20 && c <= 0xD7FF) || (c >= 0xE000 && c <= 0xFFFD) ||
         (c >= 0x10000 && c <= 0x10FFFF);
}

void append_utf8(std::string& out, unsigned long c) {
  if (c < 0x80) {
    out += char(c);
  } else if (c < 0x800) {
    out += char(0xC0 | (c >> 6));
    out += char(0x80 | (c & 0x3F));
  } else if (c < 0x10000) {
    out += char(0xE0 | (c >> 12));
    out += char(0x80 | ((c >> 6) & 0x3F));
    out += char(0x80 | (c & 0x3F));
  } else {
    out += char(0xF0 | (c >> 18));
    out += char(0x80 | ((c >> 12) & 0x3F));
    out += char(0x80 | ((c >> 6) & 0x3F));
    out += char(0x80 | (c & 0x3F));
  }
}

std::optional<unsigned long> character_reference(std::string_view name) {  // "#233" or "#xE9"
  const bool hex = name.size() > 1 && name[1] == 'x';
  const std::string_view digits = name.substr(hex ? 2 : 1);
  unsigned long c = 0;
  const auto r = std::from_chars(digits.data(), digits.data() + digits.size(), c, hex ? 16 : 10);
  if (digits.empty() || r.ec != std::errc() || r.ptr != digits.data() + digits.size() || !allowed_char(c))
    return std::nullopt;
  return c;
}

// A text run with its references decoded; nullopt when Xerces must judge it (an unknown
// entity, a malformed or forbidden reference).
std::optional<std::string> decode_references(std::string_view run) {
  std::string out;
  for (std::size_t i = 0; i < run.size();) {
    if (run[i] != '&') {
      out += run[i++];
      continue;
    }
    const auto semi = run.find(';', i);
    if (semi == npos || semi - i > 16) return std::nullopt;
    const std::string_view name = run.substr(i + 1, semi - i - 1);
    i = semi + 1;
    if (name == "amp") out += '&';
    else if (name == "lt") out += '<';
    else if (name == "gt") out += '>';
    else if (name == "quot") out += '"';
    else if (name == "apos") out += '\'';
    else if (const auto c = name.empty() || name[0] != '#' ? std::nullopt : character_reference(name))
      append_utf8(out, *c);
    else return std::nullopt;
  }
  return out;
}

// The character data from t[i] to the next tag (text runs, CDATA sections; comments skipped),
// with i moved past it. Its text when Xerces would deliver it in more than one piece (a
// reference, a CDATA section beside text): libcitygml would keep only the last. nullopt when
// it comes in one piece, holds no text (whitespace between tags, outside the root), or holds
// something for Xerces to refuse.
std::optional<std::string> split_character_data(std::string_view t, std::size_t& i) {
  std::string text;
  int pieces = 0;
  bool references = false, decodable = true;
  while (i < t.size()) {
    if (starts_with(t, i, "<!--")) {
      const auto e = t.find("-->", i + 4);
      i = e == npos ? t.size() : e + 3;
    } else if (starts_with(t, i, "<![CDATA[")) {
      const auto e = t.find("]]>", i + 9);
      if (e == npos) {  // unterminated: Xerces refuses the file
        i = t.size();
        return std::nullopt;
      }
      text.append(t.substr(i + 9, e - i - 9));
      ++pieces;
      i = e + 3;
    } else if (t[i] == '<') {
      break;
    } else {
      const std::size_t end = std::min(t.find('<', i), t.size());
      const std::string_view run = t.substr(i, end - i);
      ++pieces;
      if (run.find('&') != npos) {
        references = true;
        const auto decoded = decode_references(run);
        if (decoded) text += *decoded;
        decodable = decodable && decoded;
      } else {
        text.append(run);
      }
      i = end;
    }
  }
  const bool has_text = text.find_first_not_of(" \t\r\n") != std::string::npos;
  if (!decodable || !has_text || (!references && pieces < 2) || text.find("]]>") != std::string::npos)
    return std::nullopt;
  return text;
}

// Where the tag, processing instruction or declaration starting at t[i] == '<' ends (one past
// it, or t.size()); a declaration other than a comment or CDATA section is refused.
std::size_t markup_end(std::string_view t, std::size_t i, const std::string& path) {
  auto past = [&](std::string_view close, std::size_t from) {
    const auto e = t.find(close, from);
    return e == npos ? t.size() : e + close.size();
  };
  if (starts_with(t, i, "<!"))  // comments and CDATA sections are character data's
    io_text::fail(path,
                  "the XML has a document type or entity declaration (" + io_text::quote(t.substr(i, 24)) +
                      "): not accepted, CityGML needs none and its entities could read local files or fetch URLs");
  if (starts_with(t, i, "<?")) return past("?>", i + 2);
  char quote = 0;  // a tag: its '>' is the first one outside an attribute value
  for (++i; i < t.size(); ++i) {
    if (quote != 0) {
      if (t[i] == quote) quote = 0;
    } else if (t[i] == '"' || t[i] == '\'') {
      quote = t[i];
    } else if (t[i] == '>') {
      return i + 1;
    }
  }
  return t.size();
}

// How the markup t[i, end) changes the element depth: +1 a start tag, -1 an end tag, 0 an
// empty-element tag or a processing instruction.
int depth_change(std::string_view t, std::size_t i, std::size_t end) {
  if (starts_with(t, i, "<?")) return 0;
  if (starts_with(t, i, "</")) return -1;
  return end >= i + 2 && t[end - 1] == '>' && t[end - 2] == '/' ? 0 : 1;
}

}  // namespace

std::string safe_citygml_text(std::string text, const std::string& path) {
  text = as_utf8(std::move(text), path);
  const std::string_view t = text;
  std::string out;         // filled only once some character data is rewritten
  std::size_t copied = 0;  // t[0, copied) is in out
  int depth = 0;
  for (std::size_t i = 0; i < t.size();) {
    if (t[i] == '<' && !starts_with(t, i, "<!--") && !starts_with(t, i, "<![CDATA[")) {
      const std::size_t end = markup_end(t, i, path);
      depth = std::max(0, depth + depth_change(t, i, end));  // stray end tags bank no levels
      if (depth > kMaxElementDepth)
        io_text::fail(path, "the XML nests elements more than " + std::to_string(kMaxElementDepth) +
                                " deep: not accepted, CityGML needs a few dozen levels");
      i = end;
      continue;
    }
    const std::size_t start = i;
    if (const auto whole = split_character_data(t, i)) {
      out.append(t.substr(copied, start - copied));
      out += "<![CDATA[" + *whole + "]]>";
      copied = i;
    }
  }
  if (copied == 0) return text;
  out.append(t.substr(copied));
  return out;
}

}  // namespace lodrefine::io_xml
