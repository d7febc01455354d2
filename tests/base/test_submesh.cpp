// A mesh of some of another's faces (src/base/submesh.cpp): only the vertices the faces use, in
// order of first use, the faces' indices renumbered and their semantics and sources kept.
#include <gtest/gtest.h>

#include "lodrefine/base/submesh.h"

using namespace lodrefine;

TEST(Submesh, KeepsOnlyTheUsedVerticesInOrderOfFirstUse) {
  const std::vector<Vec3> vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {5, 5, 5}, {0, 0, 1}};
  Face a;
  a.v = {5, 1, 2};
  a.sem = Semantic::Roof;
  a.source = 7;
  a.provenance = Provenance::Scan;
  Face b;
  b.v = {2, 3, 5};
  b.sem = Semantic::Wall;
  const Mesh m = compacted(vertices, {a, b}, "part");
  EXPECT_EQ(m.id, "part");
  ASSERT_EQ(m.vertices.size(), 4u);  // vertices 0 and 4 are used by no face
  EXPECT_EQ(m.vertices[0], vertices[5]);
  EXPECT_EQ(m.vertices[1], vertices[1]);
  EXPECT_EQ(m.vertices[2], vertices[2]);
  EXPECT_EQ(m.vertices[3], vertices[3]);
  ASSERT_EQ(m.faces.size(), 2u);
  EXPECT_EQ(m.faces[0].v, (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(m.faces[1].v, (std::vector<int>{2, 3, 0}));
  EXPECT_EQ(m.faces[0].sem, Semantic::Roof);
  EXPECT_EQ(m.faces[0].source, 7);
  EXPECT_EQ(m.faces[0].provenance, Provenance::Scan);
  EXPECT_EQ(m.faces[1].sem, Semantic::Wall);
  EXPECT_EQ(m.faces[1].source, -1);
}

TEST(Submesh, NoFacesIsAnEmptyMesh) {
  const Mesh m = compacted({{0, 0, 0}, {1, 0, 0}}, {}, "none");
  EXPECT_TRUE(m.vertices.empty());
  EXPECT_TRUE(m.faces.empty());
  EXPECT_EQ(m.id, "none");
}
