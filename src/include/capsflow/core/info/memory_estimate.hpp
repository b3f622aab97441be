#pragma once
// A run's peak resident memory, estimated before it runs (`capsflow info`, the Slurm jobs' --mem):
// a fixed part and a part per element for the single layer, by its back end, and for the double
// layer at λ ≠ 1, by its back end, fitted to the peaks that runs of the built-in scene measured
// (summary.json's peak_rss_mb, 2 threads, flat facets; perf/memory/peak_memory.sh, the table in
// perf/RESULTS.md §1.9).
#include <string>

#include "capsflow/core/bie/backend_choice.hpp"
#include "capsflow/core/mesh/generation.hpp"

namespace capsflow {

struct Scene;

struct MemoryEstimate {
  double single_layer_mb = 0;  // the run without the double layer: mesh, wall, single layer, stepper, output
  double double_layer_mb = 0;  // the double layer and its solve (λ ≠ 1), 0 otherwise
  FarFieldBackend single_layer_backend = FarFieldBackend::Direct;
  FarFieldBackend double_layer_backend = FarFieldBackend::Direct;  // meaningful at λ ≠ 1 only
  double total_mb() const { return single_layer_mb + double_layer_mb; }
};

// The estimate for a mesh of these counts under the scene's fluid settings (back ends chosen as the
// run will choose them).
MemoryEstimate estimate_peak_memory(const Scene& scene, const MeshCounts& counts);

}  // namespace capsflow
