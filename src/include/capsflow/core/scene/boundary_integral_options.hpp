#pragma once
// The boundary integral's options as a scene sets them: the one place that maps fluid.* onto
// SingleLayerOptions and DoubleLayerOptions (the run's operators, `info`'s estimates and a study's
// Slurm sizing all read them from here, so they cannot disagree about the far field).
#include <string>

#include "capsflow/core/bie/double_layer.hpp"
#include "capsflow/core/bie/single_layer.hpp"
#include "capsflow/core/scene/scene.hpp"

namespace capsflow {

// fluid.tolerance resolved (docs/boundary-integral.md §4.3.2): what the direct sums, the back-end
// crossover and (λ ≠ 1) the second-kind solve use, and what the single layer's FMM promises.
struct FarFieldTolerance {
  double tolerance = 1e-6;
  double fmm_tolerance = 1e-6;
  std::string reason;  // "auto: …" or "given"
};
FarFieldTolerance far_field_tolerance(const Scene& scene);

// threads: the operators' OpenMP threads (0 = the OpenMP default).
SingleLayerOptions boundary_integral_options(const Scene& scene, int threads = 0);
// The double layer's (fluid.viscosity_ratio ≠ 1): the same far field, and fluid.reuse_identity_term.
DoubleLayerOptions double_layer_options(const Scene& scene, int threads = 0);

}  // namespace capsflow
