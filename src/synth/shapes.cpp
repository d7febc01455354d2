// The building types (see shapes.h). Building frame: metres, x/y axis-aligned where the type
// allows, the street side at y = 0 facing -y.
#include <algorithm>
#include <cmath>

#include "shapes.h"

namespace lodrefine::synth {

namespace {

Spec single_part(std::vector<int> lines, std::vector<RoofPlane> roof, Spec s) {
  s.parts.push_back({std::move(lines), std::move(roof)});
  return s;
}

Spec flat_spec(Rng& r, double z0) {
  Spec s;
  s.z0 = z0;
  const double W = r.uniform(8, 30), D = r.uniform(6, std::min(W, 16.0));
  const auto lines = rect_lines(s, 0, 0, W, D);
  return single_part(lines, {flat_roof(z0 + r.uniform(3, 15))}, s);
}

Spec gable_spec(Rng& r, double z0, bool hip) {
  Spec s;
  s.z0 = z0;
  const double D = r.uniform(6, 12), W = D + r.uniform(hip ? 2.0 : 0.0, 12.0);
  const double eave = z0 + r.uniform(3, hip ? 8 : 9), k = std::tan(radians(r.uniform(25, hip ? 45 : 50)));
  const auto lines = rect_lines(s, 0, 0, W, D);
  std::vector<RoofPlane> roof{sloped_roof({0, 0}, {0, 1}, eave, k), sloped_roof({0, D}, {0, -1}, eave, k)};
  if (hip) {
    const double k2 = std::tan(std::atan(k) + radians(r.uniform(0, 15)));
    roof.push_back(sloped_roof({0, 0}, {1, 0}, eave, k2));
    roof.push_back(sloped_roof({W, 0}, {-1, 0}, eave, k2));
  }
  return single_part(lines, roof, s);
}

Spec shed_spec(Rng& r, double z0) {
  Spec s;
  s.z0 = z0;
  const double W = r.uniform(6, 20), D = r.uniform(6, 12);
  const auto lines = rect_lines(s, 0, 0, W, D);
  const double low = z0 + r.uniform(3, 8), k = std::tan(radians(r.uniform(8, 25)));
  return single_part(lines, {sloped_roof({0, 0}, {0, 1}, low, k)}, s);
}

// A tall block with a low annex behind it and sometimes a second one at its right side; annexes
// flush with the block's sides share its footprint line.
Spec stepped_spec(Rng& r, double z0) {
  Spec s;
  s.z0 = z0;
  const double W = r.uniform(10, 20), D = r.uniform(9, 14), hA = r.uniform(9, 15);
  const bool three = r.chance(0.5);
  const auto A = rect_lines(s, 0, 0, W, D);
  s.parts.push_back({A, {flat_roof(z0 + hA)}});
  // Annex B against the back (y = D).
  const double hB = r.uniform(3, 5.5), DB = r.uniform(4, 8);
  const double bx0 = r.chance(0.5) ? 0.0 : r.uniform(1, 3);
  double bx1 = bx0 + r.uniform(5, W - bx0);
  if (bx1 > W - 1) bx1 = W;
  const int bl = bx0 == 0.0 ? A[3] : add_line(s, {bx0, D + DB}, {bx0, D});
  const int br = bx1 == W ? A[1] : add_line(s, {bx1, D}, {bx1, D + DB});
  s.parts.push_back({{A[2], br, add_line(s, {bx1, D + DB}, {bx0, D + DB}), bl}, {flat_roof(z0 + hB)}});
  if (!three) return s;
  // Annex C against the right side (x = W), of a third height, clear of B.
  const double hC = r.uniform(hB + 1.2, hA - 2.0), WC = r.uniform(4, 8);
  const double cy0 = r.chance(0.5) ? 0.0 : r.uniform(1, 2.5), cy1 = r.uniform(cy0 + 4, D - 1.5);
  const int cb = cy0 == 0.0 ? A[0] : add_line(s, {W, cy0}, {W + WC, cy0});
  s.parts.push_back({{cb, add_line(s, {W + WC, cy0}, {W + WC, cy1}), add_line(s, {W + WC, cy1}, {W, cy1}), A[1]},
                     {flat_roof(z0 + hC)}});
  return s;
}

// L: a block and a wing along its left side sharing the left facade line; flat roof.
Spec lshape_spec(Rng& r, double z0) {
  Spec s;
  s.z0 = z0;
  const double W = r.uniform(10, 24), D1 = r.uniform(6, 10), W2 = r.uniform(5, W - 4), D2 = r.uniform(4, 10);
  const RoofPlane roof = flat_roof(z0 + r.uniform(3, 12));
  const int bottom = add_line(s, {0, 0}, {W, 0}), right = add_line(s, {W, 0}, {W, D1});
  const int mid = add_line(s, {W, D1}, {0, D1}), left = add_line(s, {0, D1 + D2}, {0, 0});
  s.parts.push_back({{bottom, right, mid, left}, {roof}});
  const int wr = add_line(s, {W2, D1}, {W2, D1 + D2}), wt = add_line(s, {W2, D1 + D2}, {0, D1 + D2});
  s.parts.push_back({{mid, wr, wt, left}, {roof}});
  return s;
}

// T: a stem part running through, with a wing on each side sharing the back facade line.
Spec tshape_spec(Rng& r, double z0) {
  Spec s;
  s.z0 = z0;
  const double W = r.uniform(14, 26), Ws = r.uniform(5, 9), Ls = r.uniform(4, 9), Dc = r.uniform(6, 10);
  const double x0 = std::clamp((W - Ws) / 2 + r.uniform(-2, 2), 2.5, W - Ws - 2.5), x1 = x0 + Ws, Dt = Ls + Dc;
  const RoofPlane roof = flat_roof(z0 + r.uniform(3, 12));
  const int top = add_line(s, {W, Dt}, {0, Dt});
  const int cl = add_line(s, {x0, Dt}, {x0, 0}), cr = add_line(s, {x1, 0}, {x1, Dt});
  s.parts.push_back({{add_line(s, {x0, 0}, {x1, 0}), cr, top, cl}, {roof}});
  s.parts.push_back({{add_line(s, {0, Ls}, {x0, Ls}), cl, top, add_line(s, {0, Dt}, {0, Ls})}, {roof}});
  s.parts.push_back({{add_line(s, {x1, Ls}, {W, Ls}), add_line(s, {W, Ls}, {W, Dt}), top, cr}, {roof}});
  return s;
}

// Convex trapezoid or chamfered pentagon with oblique corners; flat or mono-pitch roof.
Spec polygon_spec(Rng& r, double z0) {
  Spec s;
  s.z0 = z0;
  const double W = r.uniform(11, 22), D = r.uniform(7, 14);
  auto skew = [&] { return r.sign() * r.uniform(1.5, 3.5); };
  std::vector<Vec2> pts;
  if (r.chance(0.5)) {
    pts = {{0, 0}, {W, 0}, {W - skew(), D}, {skew(), D}};
  } else {
    const double c1 = r.uniform(2, 5), c2 = r.uniform(2, 5);
    pts = {{0, 0}, {W, 0}, {W, D - c1}, {W - c2, D}, {skew(), D}};
  }
  std::vector<int> lines;
  for (std::size_t i = 0; i < pts.size(); ++i) lines.push_back(add_line(s, pts[i], pts[(i + 1) % pts.size()]));
  const double h = z0 + r.uniform(3, 10);
  const RoofPlane roof =
      r.chance(0.5) ? flat_roof(h) : sloped_roof({0, 0}, {0, 1}, h, std::tan(radians(r.uniform(8, 20))));
  return single_part(lines, {roof}, s);
}

}  // namespace

Spec make_spec(BuildingType t, Rng& r, double z0) {
  switch (t) {
    case BuildingType::Flat:
      return flat_spec(r, z0);
    case BuildingType::Gable:
      return gable_spec(r, z0, false);
    case BuildingType::Hip:
      return gable_spec(r, z0, true);
    case BuildingType::Shed:
      return shed_spec(r, z0);
    case BuildingType::Stepped:
      return stepped_spec(r, z0);
    case BuildingType::LShape:
      return lshape_spec(r, z0);
    case BuildingType::TShape:
      return tshape_spec(r, z0);
    case BuildingType::Polygon:
      return polygon_spec(r, z0);
  }
  throw std::logic_error("synth: unknown building type");
}


}  // namespace lodrefine::synth
