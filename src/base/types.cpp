#include "lodrefine/base/types.h"

#include <algorithm>
#include <cctype>
#include <cstring>

namespace lodrefine {

OutOfMemory::OutOfMemory(const std::string& message) noexcept {
  const std::size_t n = std::min(message.size(), sizeof what_ - 1);
  std::memcpy(what_, message.data(), n);
  what_[n] = '\0';
}

const char* semantic_name(Semantic s) {
  switch (s) {
    case Semantic::Wall: return "WallSurface";
    case Semantic::Roof: return "RoofSurface";
    case Semantic::Ground: return "GroundSurface";
    default: return "OtherSurface";
  }
}

const char* provenance_name(Provenance p) {
  switch (p) {
    case Provenance::Model: return "model";
    case Provenance::Scan: return "scan";
    case Provenance::Added: return "added";
    default: return "";
  }
}

Provenance provenance_from_group(const std::string& group) {
  std::string word;
  for (std::size_t i = 0; i <= group.size(); ++i) {
    if (i < group.size() && !std::isspace(static_cast<unsigned char>(group[i]))) {
      word += group[i];
      continue;
    }
    for (Provenance p : {Provenance::Model, Provenance::Scan, Provenance::Added})
      if (word == provenance_name(p)) return p;
    word.clear();
  }
  return Provenance::None;
}

Semantic semantic_from_name(const std::string& group) {
  std::string g = group;
  std::transform(g.begin(), g.end(), g.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (g.find("wall") != std::string::npos || g.find("facade") != std::string::npos) return Semantic::Wall;
  if (g.find("roof") != std::string::npos) return Semantic::Roof;
  if (g.find("ground") != std::string::npos || g.find("floor") != std::string::npos) return Semantic::Ground;
  return Semantic::Other;
}

}  // namespace lodrefine
