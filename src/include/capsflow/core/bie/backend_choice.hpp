#pragma once
// The boundary integral's choices: which far-field back end each operator uses and why (the
// scene's choice, or for "auto" a measured FMM/direct crossover: the single layer's own table
// below, the double layer's the stresslet FMM's, fmm/calibration.hpp), and which surface it
// integrates over and with which far-field rule.
#include <cstddef>
#include <string>

#include <Eigen/Core>

#include "capsflow/core/named_enum.hpp"

namespace capsflow {

enum class BackendRequest { Auto, Fmm, Direct };  // what the scene asks for
enum class FarFieldBackend { Direct, Fmm };       // what is used
enum class SurfaceGeometry { Flat, Curved };      // flat P1 facets, or their quadratic lift

inline constexpr NameTable<BackendRequest, 3> kBackendRequestNames{
    {{BackendRequest::Auto, "auto"}, {BackendRequest::Fmm, "fmm"}, {BackendRequest::Direct, "direct"}}};
inline constexpr NameTable<FarFieldBackend, 2> kFarFieldBackendNames{
    {{FarFieldBackend::Direct, "direct"}, {FarFieldBackend::Fmm, "fmm"}}};
inline constexpr NameTable<SurfaceGeometry, 2> kSurfaceGeometryNames{
    {{SurfaceGeometry::Flat, "flat"}, {SurfaceGeometry::Curved, "curved"}}};
constexpr const auto& name_table(BackendRequest) { return kBackendRequestNames; }
constexpr const auto& name_table(FarFieldBackend) { return kFarFieldBackendNames; }
constexpr const auto& name_table(SurfaceGeometry) { return kSurfaceGeometryNames; }
// The far field's element rule (docs/boundary-integral.md §4.2.1); Auto: edge midpoints on flat
// facets, Gauss points on curved elements.
enum class FarFieldRule { Auto, EdgeMidpoints, GaussPoints };
inline constexpr NameTable<FarFieldRule, 3> kFarFieldRuleNames{
    {{FarFieldRule::Auto, "auto"}, {FarFieldRule::EdgeMidpoints, "edge_midpoints"}, {FarFieldRule::GaussPoints, "gauss_points"}}};
constexpr const auto& name_table(FarFieldRule) { return kFarFieldRuleNames; }

// Which operator's far field is summed: the single layer's Stokeslets (single_layer.hpp) or the
// double layer's stresslets (double_layer.hpp).
enum class FarFieldKernel { SingleLayer, DoubleLayer };

// Both operators ask the FMM for this fraction of fluid.tolerance: its calibration is a relative
// L2 error over the targets, capsflow promises the tolerance relative to max |v| at every node.
inline constexpr double kFmmToleranceMargin = 0.25;

// The single layer's FMM/direct crossover, measured with its own far field: edge-midpoint
// sources (3 per node) summed directly by eight-lane Stokeslet blocks (single-precision pairs
// from 1e-5, double below) against the FMM's set-up and one evaluation at the order the tolerance
// calls for (perf/bie/crossover.sh on a quiet machine, perf/RESULTS.md §1.4, data
// perf/bie/crossover.jsonl). Rows from loose to tight; a row applies to fluid.tolerance >= its
// tolerance. "auto" sums directly while n_src·n_trg < crossover².
struct SingleLayerCrossoverRow {
  double tolerance;
  std::size_t crossover;  // sqrt(n_src·n_trg)
  bool measured;          // false: direct was faster at every measured size; the crossover is extrapolated
};
// Where the FMM's time (log-log between the measured sizes) meets direct's (perf/bie/crossover.py),
// measured with the FMM's calibrated leaf sizes (fmm/calibration.hpp):
// 10 432, 14 138, 16 130, 15 805, 16 103, 23 951 at 1e-3 … 1e-8, rounded up; 1e-6 takes 1e-5's
// 16 200 (2 % apart, within the repeats' spread: a tighter tolerance never switches earlier).
// Every row is measured: the FMM wins at the largest size of the set (octahedron level 6, 28 400)
// at every tolerance (with leaves of 200–600 direct won there from 1e-6 on, and the rows had to be
// extrapolated to 31 000–50 000). From 1e-6 on the direct sum pairs in double (~1.6× the time per
// pair), which is why 1e-6 switches no later than 1e-5 although its FMM order is higher. The rows
// were measured with AVX-512 and double pairs in the FMM's near field; the FMM's single-precision
// pairs (1e-5 and looser) make it cheaper there, so those crossovers are, if anything, late.
inline constexpr SingleLayerCrossoverRow kSingleLayerCrossover[] = {
    {1e-3, 10500, true}, {1e-4, 14200, true}, {1e-5, 16200, true},
    {1e-6, 16200, true}, {1e-7, 16200, true}, {0.0, 24000, true},
};
const SingleLayerCrossoverRow& single_layer_crossover(double tolerance);

// True when the single layer's far field sums single-precision pairs (tolerance >= 1e-5, builds
// with AVX-512 or AVX2): every pair of the direct sum, the FMM's direct near field.
bool uses_mixed_precision(double tolerance);

// The double layer's FMM order, chosen by the error the second-kind solve sees: relative to the
// density u in the nodal-area norm (gmres.hpp's contract: an error of at most ε‖u‖), where
// fmm/calibration.hpp measures relative to the image. For a smooth density the two agree
// (|D u| ≈ |u|/2); for a rough one — a Krylov vector — the image is 50× smaller than the density,
// and the calibration's hardest case (random f with outward normals) asked for p = 11 at
// fluid.tolerance = 1e-6 where p = 9 stays 7× below the need at half the cost. Worst over a smooth
// and a random density and icosphere levels 4–6 mapped to an a/b = 2 spheroid, against the direct
// sum (perf/bie/double_layer_fmm_order, perf/RESULTS.md §2.2): relative L2 error and max error
// relative to max |u|.
struct DoubleLayerOrderRow {
  int order;
  double l2, max;
};
inline constexpr DoubleLayerOrderRow kDoubleLayerOrders[] = {
    {4, 7.8e-4, 3.2e-3}, {5, 4.0e-4, 2.4e-3}, {6, 2.7e-5, 7.9e-5}, {7, 1.4e-6, 7.3e-6}, {8, 4.9e-7, 1.8e-6},
    {9, 3.8e-8, 2.4e-7}, {10, 9.2e-9, 6.1e-8}, {11, 2.7e-9, 1.9e-8},
};
// The stresslet FMM tolerance (fmm/calibration.hpp's) of the lowest order above whose L2 error,
// doubled for margin, is within l2_allowed and whose max error is within max_allowed (both
// relative to the density); the FMM asked for it runs that order. Beyond the table: l2_allowed
// itself, relative to the image (stricter).
double double_layer_fmm_tolerance(double l2_allowed, double max_allowed);
// The tolerance fluid.tolerance asks of the double layer's exact applications: L2 within
// kFmmToleranceMargin × tolerance, max within tolerance (the single layer's promise).
inline double double_layer_fmm_tolerance(double tolerance) {
  return double_layer_fmm_tolerance(kFmmToleranceMargin * tolerance, tolerance);
}

// The back end of one operator's far field for n_sources sources (the single layer's and double
// layer's: one per edge, the edge midpoints, on flat facets; 3 per element on curved ones; see
// far_field_source_count in single_layer.hpp) and n_targets targets (the nodes): the scene's
// choice, or for "auto" that operator's measured crossover (the single layer's table above; the
// double layer's fmm::direct_crossover<fmm::Stresslet> at kFmmToleranceMargin × tolerance, the
// calibration's own rule, measured right at the boundary integral's sizes: backend_choice.cpp);
// `reason` says why.
FarFieldBackend choose_backend(BackendRequest requested, FarFieldKernel kernel, Eigen::Index n_sources, Eigen::Index n_targets,
                               double tolerance, std::string* reason);

// With the FMM chosen by "auto" for the double layer: whether its set-up pass — the three unit
// constants of D̃[1] and the first application, four densities for the FMM — sums directly
// instead (double_layer.cpp: the pair geometry is shared by all four, 9 outputs per pair), while
// the Krylov steps keep the FMM. Measured at 81 920 elements (sqrt(sources × targets) = 70 950,
// p = 11, perf/bie/double_layer_bench --levels 6 --repeat 3 --threads 2 --backend direct|fmm): CPU s
// 3.4 against the FMM's 5.3 on a loaded machine, 2.84 against 3.79 (wall 1.42 against
// 1.91) on a quiet one, so the direct pass wins up to ~1.3–1.5× that size, 3.3–3.8×
// the one-density crossover (28 900). With the FMM at p = 9 (double_layer_fmm_tolerance)
// its pass is cheaper: at 81 920 elements it now wins (`--reuse 0`, wall s, a slow host: fused
// set-up 2.75 against 3.95 direct), so the factor is below 70 950 / 28 900 = 2.45; no level of the
// icosphere lies between 28 900 and 2 × 28 900, where the factor decides. `reason` gets a clause
// appended when the pass is direct.
inline constexpr double kDirectSetUpCrossoverFactor = 2.0;
bool double_layer_set_up_direct(BackendRequest requested, FarFieldBackend chosen, Eigen::Index n_sources, Eigen::Index n_targets,
                                double tolerance, std::string* reason = nullptr);

}  // namespace capsflow
