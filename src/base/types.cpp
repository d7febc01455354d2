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

Semantic semantic_from_name(const std::string& group) {
  std::string g = group;
  std::transform(g.begin(), g.end(), g.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (g.find("wall") != std::string::npos || g.find("facade") != std::string::npos) return Semantic::Wall;
  if (g.find("roof") != std::string::npos) return Semantic::Roof;
  if (g.find("ground") != std::string::npos || g.find("floor") != std::string::npos) return Semantic::Ground;
  return Semantic::Other;
}

}  // namespace lodrefine
