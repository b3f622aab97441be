#pragma once
// The boundary integral's choices: which far-field back end it uses and why (the scene's choice,
// or for "auto" the measured FMM/direct crossover of capsflow::fmm, fmm/calibration.hpp), and
// which surface it integrates over.
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

// True when the direct far field sums single-precision pairs (tolerance >= 1e-5, AVX-512 builds).
bool uses_mixed_precision(FarFieldBackend b, double tolerance);

// The back end for n_sources far-field sources (SingleLayer: one per edge, the edge midpoints) and
// n_targets targets (the nodes): the scene's choice, or for "auto" the measured crossover;
// `reason` says why.
FarFieldBackend choose_backend(BackendRequest requested, Eigen::Index n_sources, Eigen::Index n_targets, double tolerance,
                               std::string* reason);

}  // namespace capsflow
