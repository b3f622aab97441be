#pragma once
// capsflow::fmm::Surface — KIFMM equivalent/check surfaces: the 6(p−1)²+2 boundary nodes of a
// p×p×p lattice on the cube [−1,1]^3 (unit half-width). A box of centre c and half-width r uses
// c + α·r·s with α = kRadInner (upward equivalent, downward check) or kRadOuter (upward check,
// downward equivalent). lattice[3k..3k+2] = integer lattice position of point k (used by M2L).
#include <stdexcept>
#include <vector>

namespace capsflow::fmm {

constexpr double kRadInner = 1.05;
constexpr double kRadOuter = 2.95;

struct Surface {
  int p = 0;
  int n = 0;
  std::vector<double> x, y, z;  // unit half-width coordinates
  std::vector<int> lattice;     // (ax, ay, az) of point k at 3k..3k+2, each in [0, p)

  explicit Surface(int order = 0) {
    if (order == 0) return;
    if (order < 2) throw std::invalid_argument("capsflow::fmm: order must be >= 2");
    p = order;
    for (int ax = 0; ax < p; ++ax)
      for (int ay = 0; ay < p; ++ay)
        for (int az = 0; az < p; ++az) {
          const bool boundary = ax == 0 || ay == 0 || az == 0 || ax == p - 1 || ay == p - 1 || az == p - 1;
          if (!boundary) continue;
          x.push_back(2.0 * ax / (p - 1) - 1.0);
          y.push_back(2.0 * ay / (p - 1) - 1.0);
          z.push_back(2.0 * az / (p - 1) - 1.0);
          lattice.insert(lattice.end(), {ax, ay, az});
        }
    n = static_cast<int>(x.size());
  }

  /// coordinates of the surface of a box (centre c, half-width r) scaled by alpha, into x/y/z out
  void place(const double c[3], double r_alpha, double* ox, double* oy, double* oz) const {
    for (int k = 0; k < n; ++k) {
      ox[k] = c[0] + r_alpha * x[k];
      oy[k] = c[1] + r_alpha * y[k];
      oz[k] = c[2] + r_alpha * z[k];
    }
  }
};

}  // namespace capsflow::fmm
