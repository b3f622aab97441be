#pragma once
// The single layer at arbitrary targets off the surface (the velocity field around the capsule),
// with a near-surface check: the far-field rule of an element is accurate only for targets farther
// than about two element sizes; nearer elements are integrated by adaptive subdivision.
#include <vector>

#include "capsflow/core/bie/single_layer.hpp"

namespace capsflow {

// Off-surface evaluation report: per target, the distance to the surface relative to the size
// of the nearest element; targets with ratio < near_ratio get an adaptive quadrature on the
// nearby elements (reported as refined), those below min_ratio are too close to trust.
struct OffSurfaceReport {
  std::vector<double> distance_ratio;
  long refined = 0, too_close = 0;
  static constexpr double near_ratio = 2.0, min_ratio = 1e-3;
};

// u at `targets` for the load q on the surface x (sources built by S for this x and q).
void evaluate_off_surface(SingleLayer& S, const Points& x, const Points& q, const Points& targets, Points& u,
                          OffSurfaceReport* report = nullptr);

}  // namespace capsflow
