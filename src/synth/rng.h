// Random numbers and small plane helpers shared by the generator's modules (internal).
#pragma once
#include <cmath>
#include <cstdint>
#include <random>

#include "lodrefine/base/geometry.h"
#include "lodrefine/base/types.h"

namespace lodrefine::synth {

// Random numbers. mt19937_64's sequence is fixed by the standard but the library distributions
// are not, so the mappings are our own: the shipped samples regenerate identically everywhere.
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : g_(seed) {}
  double uniform() { return double(g_() >> 11) * (1.0 / 9007199254740992.0); }  // [0, 1)
  double uniform(double a, double b) { return a + (b - a) * uniform(); }
  int integer(int lo, int hi) { return lo + int(g_() % std::uint64_t(hi - lo + 1)); }  // inclusive
  bool chance(double p) { return uniform() < p; }
  double sign() { return chance(0.5) ? 1.0 : -1.0; }
  double normal() {  // Box-Muller
    double u = uniform();
    while (u <= 0.0) u = uniform();
    return std::sqrt(-2.0 * std::log(u)) * std::cos(2.0 * kPi * uniform());
  }
  // Truncated at 3.5 sigma so "within 4 sigma of the plane" holds for every point.
  double noise(double sigma) {
    double z = normal();
    while (std::abs(z) > 3.5) z = normal();
    return sigma * z;
  }
  Vec2 unit2() {
    const double a = uniform(0.0, 2.0 * kPi);
    return {std::cos(a), std::sin(a)};
  }
  Vec3 unit3() {
    Vec3 v(normal(), normal(), normal());
    return v.norm() > 1e-12 ? Vec3(v.normalized()) : Vec3(Vec3::UnitZ());
  }

 private:
  std::mt19937_64 g_;
};

inline std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

inline double cross2(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }
inline Vec2 xy(const Vec3& p) { return p.head<2>(); }

}  // namespace lodrefine::synth
