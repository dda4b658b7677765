#include "algorithms/circle/diamond_angle.hpp"

#include <cmath>
#include <cstring>

#include "algorithms/circle/pixel_pass.hpp"

namespace facet::diamond_angle {

double of(double dx, double dy) {
  const double sum = std::abs(dx) + std::abs(dy);
  const double q = dy / (sum > 0.0 ? sum : 1.0);
  return dx < 0.0 ? 2.0 - q : (dy < 0.0 ? 4.0 + q : q);
}

int binOf(double dx, double dy, int bins) {
  const int b = static_cast<int>(of(dx, dy) / 4.0 * bins);
  return b < bins - 1 ? b : bins - 1;
}

// Written out as vectors (pixel_pass.hpp): a run of an annulus is a dozen pixels, for which a loop
// the compiler vectorises spent more instructions in its set-up and remainder than in its body.
FACET_PIXEL_PASS void rowBins(int x0, int n, double centreX, double dy, int bins,
                              int* __restrict bin) {
  using namespace pixel_pass;
  const Ints4 last = Ints4{} + (bins - 1);
  for (int i = 0; i < n; i += 4) {
    const Doubles4 dx = (static_cast<double>(x0 + i) + kLane) - centreX;
    const Doubles4 sum = (dx < 0.0 ? -dx : dx) + std::abs(dy);
    const Doubles4 q = dy / (sum > 0.0 ? sum : Doubles4{} + 1.0);
    const Doubles4 turn = dx < 0.0 ? 2.0 - q : (dy < 0.0 ? 4.0 + q : q);
    const Ints4 b = __builtin_convertvector(turn / 4.0 * static_cast<double>(bins), Ints4);
    const Ints4 clamped = b < last ? b : last;
    std::memcpy(bin + i, &clamped, sizeof clamped);
  }
}

}  // namespace facet::diamond_angle
