#include "capsflow/core/info/memory_estimate.hpp"

#include "capsflow/core/bie/double_layer.hpp"
#include "capsflow/core/bie/single_layer.hpp"
#include "capsflow/core/scene/boundary_integral_options.hpp"
#include "capsflow/core/scene/scene.hpp"

namespace capsflow {

namespace {
// Peak RSS = fixed + per element, in MB, fitted to short runs of the built-in scene (γ̇t = 0.001,
// 2 threads, flat facets; perf/memory/peak_memory.sh, perf/RESULTS.md §1.9) at the two largest
// sizes of each back end, and anchored where a long run measured more.
struct Linear {
  double fixed_mb, per_element_mb;
  double at(long elements) const { return fixed_mb + per_element_mb * static_cast<double>(elements); }
};
// Direct single layer: 37 and 93 MB at 5 120 and 20 480 elements (23 MB at 1 280: within 1 MB).
constexpr Linear kSingleLayerDirect{18, 3.6e-3};
// FMM single layer, by the order its tolerance calls for (the operators and the per-box surface
// vectors grow with p²). p ≤ 8 (the default "auto", 1e-5): 4.37 kB per element between 81 920 and
// 327 680 elements (575 and 1 649 MB); the fixed part from the 653 MB of a long run at 81 920 (Fig. 4
// to γ̇t = 5, §1.1), 78 MB more than the short run; 6.02 GB at 1 310 720 elements, where a run
// measured 5.83 GB.
constexpr Linear kSingleLayerFmmUpToP8{295, 4.37e-3};
// p ≥ 9 (fluid.tolerance 1e-6): 4.95 kB per element between 81 920 and 327 680 elements (772 and
// 1 986 MB); the fixed part from the 0.88 GB of a long run at 81 920, 110 MB more than the short
// run; 6.96 GB at 1 310 720 elements, where a run measured 6.75 GB. Orders above 9 were not measured.
constexpr Linear kSingleLayerFmmFromP9{475, 4.95e-3};
constexpr int kLargestOrderOfTheSmallerFit = 8;
// The double layer with the direct far field adds 2.1 kB per element (43 MB at 20 480, 11 MB at 5 120).
constexpr Linear kDoubleLayerDirect{0, 2.1e-3};
// With the stresslet FMMs: 9.0 kB per element between 81 920 and 327 680 elements (1 997 and
// 4 211 MB above λ = 1); the fixed part from the long run at 81 920 (3.62 GB in all: 2.74 GB
// above λ = 1), whose inexact Krylov steps had built the lower-order FMMs a short run never takes.
constexpr Linear kDoubleLayerFmm{2000, 9.0e-3};
}  // namespace

MemoryEstimate estimate_peak_memory(const Scene& scene, const MeshCounts& counts) {
  MemoryEstimate m;
  const SingleLayerOptions sl = boundary_integral_options(scene);
  m.single_layer_backend = choose_backend(scene.fluid.backend, FarFieldKernel::SingleLayer,
                                          far_field_source_count(sl, counts.elements, counts.edges), counts.nodes,
                                          scene.fluid.tolerance, nullptr);
  if (m.single_layer_backend == FarFieldBackend::Fmm) {
    const bool smaller = single_layer_fmm_order(sl) <= kLargestOrderOfTheSmallerFit;
    m.single_layer_mb = (smaller ? kSingleLayerFmmUpToP8 : kSingleLayerFmmFromP9).at(counts.elements);
  } else {
    m.single_layer_mb = kSingleLayerDirect.at(counts.elements);
  }
  if (scene.fluid.viscosity_ratio != 1.0) {
    const DoubleLayerOptions dl = double_layer_options(scene);
    m.double_layer_backend = choose_backend(scene.fluid.backend, FarFieldKernel::DoubleLayer,
                                            far_field_source_count(dl, counts.elements, counts.edges), counts.nodes,
                                            scene.fluid.tolerance, nullptr);
    m.double_layer_mb = (m.double_layer_backend == FarFieldBackend::Fmm ? kDoubleLayerFmm : kDoubleLayerDirect).at(counts.elements);
  }
  return m;
}

}  // namespace capsflow
