// The building types (see shapes.h). Building frame: metres, x/y axis-aligned where the type
// allows. The street-facade types (recess, bay, setback) face the street at y = 0 (towards -y).
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

// ---------------------------------------------------------------------------------------------
// Street-facade types: the truth's street facade has detail (a recess, a bay, a second facade
// line) that the coarse model generalises away: its parts are the plain block [0,W]x[0,D]
// (lines front, right, back, left), whose front line the perturbation moves.

// Flat (half), mono-pitch rising away from the street or gabled with the ridge along it; one
// roof for every part, so the parts' walls between each other are interior.
std::vector<RoofPlane> street_roof(Rng& r, double z0, double D) {
  const double u = r.uniform();
  if (u < 0.5) return {flat_roof(z0 + r.uniform(4, 15))};
  const double eave = z0 + r.uniform(4, 9);
  if (u < 0.75) return {sloped_roof({0, 0}, {0, 1}, eave, std::tan(radians(r.uniform(8, 20))))};
  const double k = std::tan(radians(r.uniform(25, 45)));
  return {sloped_roof({0, 0}, {0, 1}, eave, k), sloped_roof({0, D}, {0, -1}, eave, k)};
}

struct Block {
  Spec s;
  double W, D;
  int front, right, back, left;
  std::vector<RoofPlane> roof;
};

Block street_block(Rng& r, double z0, double wmin, double wmax) {
  Block b;
  b.s.z0 = z0;
  b.W = r.uniform(wmin, wmax), b.D = r.uniform(8, 14);
  const auto l = rect_lines(b.s, 0, 0, b.W, b.D);
  b.front = l[0], b.right = l[1], b.back = l[2], b.left = l[3];
  b.roof = street_roof(r, z0, b.D);
  b.s.generalised = {{{b.front, b.right, b.back, b.left}, b.roof}};
  b.s.coarse_front = b.front;
  b.s.street_normal = {0, -1};
  return b;
}

// A full-height recess (entrance, loggia) 2.5-6 m wide and 1-2.5 m deep in the street facade:
// a back wall and two returns. Parts: left of it, behind it, right of it.
Spec recess_spec(Rng& r, double z0) {
  Block b = street_block(r, z0, 12, 24);
  Spec& s = b.s;
  const double w = r.uniform(2.5, std::min(6.0, b.W - 6)), d = r.uniform(1.0, 2.5);
  const double x0 = r.uniform(2.5, b.W - w - 2.5), x1 = x0 + w;
  const int ra = add_line(s, {x0, 0}, {x0, b.D}), rb = add_line(s, {x1, b.D}, {x1, 0});
  const int back_wall = add_line(s, {x0, d}, {x1, d});
  s.parts = {{{b.front, ra, b.back, b.left}, b.roof},
             {{back_wall, rb, b.back, ra}, b.roof},
             {{b.front, b.right, b.back, rb}, b.roof}};
  s.street = {b.front, ra, back_wall, rb};
  return s;
}

// A bay / risalit 2.5-6 m wide standing 0.6-1.5 m out of the street facade, full height.
Spec bay_spec(Rng& r, double z0) {
  Block b = street_block(r, z0, 11, 24);
  Spec& s = b.s;
  const double w = r.uniform(2.5, std::min(6.0, b.W - 5)), d = r.uniform(0.6, 1.5);
  const double x0 = r.uniform(2.0, b.W - w - 2.0), x1 = x0 + w;
  const int bl = add_line(s, {x0, 0}, {x0, -d}), bf = add_line(s, {x0, -d}, {x1, -d});
  const int br = add_line(s, {x1, -d}, {x1, 0});
  s.parts = {{{b.front, b.right, b.back, b.left}, b.roof}, {{bf, br, b.front, bl}, b.roof}};
  s.street = {b.front, bl, bf, br};
  return s;
}

// A street facade line that steps back 0.8-2.5 m part-way along; the coarse model's generalised
// front follows either of the two lines.
Spec setback_spec(Rng& r, double z0) {
  Block b = street_block(r, z0, 14, 26);
  Spec& s = b.s;
  const double xs = r.uniform(0.35, 0.65) * b.W, d = r.uniform(0.8, 2.5);
  const int step = add_line(s, {xs, 0}, {xs, b.D});
  const bool left_forward = r.chance(0.5);
  const int rear = left_forward ? add_line(s, {xs, d}, {b.W, d}) : add_line(s, {0, d}, {xs, d});
  const int left_front = left_forward ? b.front : rear, right_front = left_forward ? rear : b.front;
  s.parts = {{{left_front, step, b.back, b.left}, b.roof}, {{right_front, b.right, b.back, step}, b.roof}};
  s.street = {b.front, step, rear};
  if (r.chance(0.5)) s.generalised[0].lines[0] = s.coarse_front = rear;
  return s;
}

}  // namespace

Spec make_spec(BuildingType t, Rng& r, double z0) {
  switch (t) {
    case BuildingType::Flat: return flat_spec(r, z0);
    case BuildingType::Gable: return gable_spec(r, z0, false);
    case BuildingType::Hip: return gable_spec(r, z0, true);
    case BuildingType::Shed: return shed_spec(r, z0);
    case BuildingType::Stepped: return stepped_spec(r, z0);
    case BuildingType::LShape: return lshape_spec(r, z0);
    case BuildingType::TShape: return tshape_spec(r, z0);
    case BuildingType::Polygon: return polygon_spec(r, z0);
    case BuildingType::Recess: return recess_spec(r, z0);
    case BuildingType::Bay: return bay_spec(r, z0);
    case BuildingType::Setback: return setback_spec(r, z0);
  }
  throw std::logic_error("synth: unknown building type");
}

}  // namespace lodrefine::synth
