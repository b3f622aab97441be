#pragma once
// The boundary integral's options as a scene sets them: the one place that maps fluid.* onto
// SingleLayerOptions and DoubleLayerOptions (the run's operators, `info`'s estimates and a study's
// Slurm sizing all read them from here, so they cannot disagree about the far field).
#include "capsflow/core/bie/double_layer.hpp"
#include "capsflow/core/bie/single_layer.hpp"
#include "capsflow/core/scene/scene.hpp"

namespace capsflow {

// threads: the operators' OpenMP threads (0 = the OpenMP default).
SingleLayerOptions boundary_integral_options(const Scene& scene, int threads = 0);
// The double layer's (fluid.viscosity_ratio ≠ 1): the same far field, and fluid.reuse_identity_term.
DoubleLayerOptions double_layer_options(const Scene& scene, int threads = 0);

}  // namespace capsflow
