// A 10 x 6 m box as synth's shapes spell it (a spec of one part over four footprint lines), for
// the tests of synth's internal modules (tests/synth/test_shell.cpp, test_perturb.cpp,
// test_scan.cpp).
#pragma once
#include <utility>
#include <vector>

#include "synth/shapes.h"

namespace lodrefine::synth_fixtures {

// The footprint [0,10] x [0,6] (lines 0..3 counter-clockwise from y = 0) under `roof`.
inline synth::Spec box_spec(std::vector<synth::RoofPlane> roof = {synth::flat_roof(5.0)}) {
  synth::Spec s;
  synth::Part p;
  p.lines = synth::rect_lines(s, 0, 0, 10, 6);
  p.roof = std::move(roof);
  s.parts = {p};
  return s;
}

// Its shell under a flat roof 5 m up.
inline Mesh box_mesh() { return synth::build_mesh(box_spec()); }

}  // namespace lodrefine::synth_fixtures
