// A mesh of some of another's faces (see submesh.h).
#include "lodrefine/base/submesh.h"

namespace lodrefine {

Mesh compacted(const std::vector<Vec3>& vertices, std::vector<Face> faces, const std::string& id) {
  Mesh out;
  out.id = id;
  std::vector<int> map(vertices.size(), -1);
  for (Face& f : faces)
    for (int& i : f.v) {
      int& to = map[std::size_t(i)];
      if (to < 0) to = int(out.vertices.size()), out.vertices.push_back(vertices[std::size_t(i)]);
      i = to;
    }
  out.faces = std::move(faces);
  return out;
}

}  // namespace lodrefine
