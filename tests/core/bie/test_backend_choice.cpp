// The far-field back end (bie/backend_choice.hpp): the scene's request, the measured FMM/direct
// crossover for "auto" (fmm/calibration.hpp: direct while n_src·n_trg < c², c per tolerance), the
// single-precision pairs of the direct sum, and the source count the single layer passes.
#include <gtest/gtest.h>

#include <cmath>

#include "capsflow/core/bie/backend_choice.hpp"
#include "capsflow/core/bie/single_layer.hpp"
#include "capsflow/core/mesh/generation.hpp"
#include "capsflow/core/mesh/topology.hpp"
#include "capsflow/fmm/calibration.hpp"
#include "capsflow/fmm/direct_sum_mixed.hpp"

using namespace capsflow;

TEST(BackendChoice, AutoSwitchesAtTheCrossoverProduct) {
  for (double tol : {1e-3, 1e-6, 1e-8}) {
    const auto c = static_cast<Eigen::Index>(fmm::direct_crossover(tol));
    std::string why;
    // Sources = 3 × targets, as the single layer has them (edges = 3/2 elements ≈ 3 nodes): the
    // product just below c² is direct, just above it the FMM.
    const Eigen::Index n_trg = c / 2, below = (c * c - 1) / n_trg, above = (c * c) / n_trg + 1;
    EXPECT_EQ(choose_backend(BackendRequest::Auto, below, n_trg, tol, &why), FarFieldBackend::Direct) << tol;
    EXPECT_NE(why.find("below"), std::string::npos) << why;
    EXPECT_NE(why.find(std::to_string(below) + " sources"), std::string::npos) << why;
    EXPECT_EQ(choose_backend(BackendRequest::Auto, above, n_trg, tol, &why), FarFieldBackend::Fmm) << tol;
    EXPECT_NE(why.find("above"), std::string::npos) << why;
  }
}

TEST(BackendChoice, ASceneRequestIsHonouredWhateverTheSize) {
  std::string why;
  EXPECT_EQ(choose_backend(BackendRequest::Fmm, 10, 10, 1e-6, &why), FarFieldBackend::Fmm);
  EXPECT_NE(why.find("forced by the scene"), std::string::npos) << why;
  EXPECT_EQ(choose_backend(BackendRequest::Direct, 10'000'000, 1'000'000, 1e-6, &why), FarFieldBackend::Direct);
  EXPECT_NE(why.find("fluid.backend = \"direct\""), std::string::npos) << why;
}

TEST(BackendChoice, SinglePrecisionPairsOnlyForTheDirectSumFromTolerance1e5) {
  // 1e-5 leaves a 20× margin over the pairs' ~5e-7 (fmm/direct_sum_mixed.hpp).
  EXPECT_EQ(uses_mixed_precision(FarFieldBackend::Direct, 1e-5), fmm::kMixedPrecisionDirectSum);
  EXPECT_EQ(uses_mixed_precision(FarFieldBackend::Direct, 1e-3), fmm::kMixedPrecisionDirectSum);
  EXPECT_FALSE(uses_mixed_precision(FarFieldBackend::Direct, 9.9e-6));
  EXPECT_FALSE(uses_mixed_precision(FarFieldBackend::Fmm, 1e-3));
  std::string why;
  choose_backend(BackendRequest::Direct, 100, 100, 1e-4, &why);
  EXPECT_EQ(why.find("single precision") != std::string::npos, fmm::kMixedPrecisionDirectSum) << why;
}

TEST(BackendChoice, TheSingleLayerCountsOneSourcePerEdge) {
  // Icosphere levels 2 and 5: 960 / 30 720 edge sources; the choice must be the one for that count
  // (level 5 is decided by the calibration, whichever way it falls).
  for (int level : {2, 5}) {
    const SurfaceMesh m = make_sphere_mesh(BaseSolid::Icosahedron, level);
    SingleLayerOptions o;
    const SingleLayer S(m.triangles, m.num_nodes(), o);
    const Eigen::Index edges = mesh_edges(m).rows();
    EXPECT_EQ(S.far_field_sources(), edges);
    EXPECT_EQ(edges * 2, 3 * m.num_elements());
    EXPECT_EQ(S.backend(), choose_backend(BackendRequest::Auto, edges, m.num_nodes(), o.tolerance, nullptr)) << level;
  }
}
