// Compressive tension (health/membrane_compression.hpp) on deformations whose tensions are known
// in closed form: the neo-Hookean thin sheet, T_i = G_s/(λ1 λ2) (λ_i² − 1/(λ1 λ2)²).
#include <gtest/gtest.h>

#include <cmath>

#include "capsflow/core/health/membrane_compression.hpp"
#include "capsflow/core/mesh/generation.hpp"

using namespace capsflow;

namespace {
double nh_equibiaxial_tension(double l) { return 1.0 - std::pow(l, -6.0); }  // G_s = 1
// Equal stretches are a double eigenvalue of the facet's 2×2 strain problem: its discriminant
// leaves √ε ≈ 1.5e-8 in each stretch, times dT/dλ = 6 λ⁻⁷ ≈ 12.5 at λ = 0.9: 2e-7 at most.
constexpr double kEquibiaxialRoundOff = 5e-7;
}  // namespace

TEST(MembraneCompression, NoneAtRestOrInflated) {
  const SurfaceMesh ref = make_sphere_mesh(BaseSolid::Icosahedron, 3);
  const shell::MembraneLaw law = shell::make_law(shell::LawKind::NeoHookean, 1.0);  // G_s = 1
  const MembraneCompression rest = membrane_compression(ref, ref.vertices, law);
  EXPECT_EQ(rest.compressed_area_fraction, 0.0);
  EXPECT_GT(rest.min_tension, -kCompressionRoundOff);  // round-off of the stretches only
  const MembraneCompression inflated = membrane_compression(ref, 1.1 * ref.vertices, law);
  EXPECT_EQ(inflated.compressed_area_fraction, 0.0);
  EXPECT_EQ(inflated.min_tension, 0.0);
}

TEST(MembraneCompression, UniformShrinkCompressesEveryFacetByTheClosedForm) {
  const SurfaceMesh ref = make_sphere_mesh(BaseSolid::Icosahedron, 3);
  const shell::MembraneLaw law = shell::make_law(shell::LawKind::NeoHookean, 1.0);
  // x = 0.9 X maps every flat facet onto a copy shrunk by 0.9 in both directions.
  const MembraneCompression m = membrane_compression(ref, 0.9 * ref.vertices, law);
  EXPECT_NEAR(m.compressed_area_fraction, 1.0, 1e-14);  // every facet; round-off of the area sums
  EXPECT_NEAR(m.min_tension, nh_equibiaxial_tension(0.9), kEquibiaxialRoundOff);  // −0.8817
}

TEST(MembraneCompression, AShrunkCapIsFoundWhereItIs) {
  const SurfaceMesh ref = make_sphere_mesh(BaseSolid::Icosahedron, 3);
  const shell::MembraneLaw law = shell::make_law(shell::LawKind::NeoHookean, 1.0);
  // The cap z > 0.5 shrunk by 0.9 towards the centre: its facets are equibiaxially compressed,
  // the facets around z < 0.4 untouched; those across the rim are distorted.
  Points x = ref.vertices;
  for (Eigen::Index i = 0; i < x.rows(); ++i)
    if (ref.vertices(i, 2) > 0.5) x.row(i) *= 0.9;
  const Vec3 north(0, 0, 1), south(0, 0, -1);
  const MembraneCompression m = membrane_compression(ref, x, law, north, 0.3);
  EXPECT_LE(m.min_tension, nh_equibiaxial_tension(0.9) + kEquibiaxialRoundOff);  // the cap at least
  EXPECT_GT(m.where.z(), 0.3);                                    // in the cap or on its rim
  // The cap is a quarter of the sphere's area (Archimedes: (1 − 0.5)/2), shrunk by 0.81: about
  // 21 % of the deformed area, plus part of the rim; the rest is not compressed.
  EXPECT_GT(m.compressed_area_fraction, 0.18);
  EXPECT_LT(m.compressed_area_fraction, 0.30);
  // Near the pole every facet is inside the cap: the closed form itself.
  EXPECT_NEAR(m.min_tension_near_probe, nh_equibiaxial_tension(0.9), kEquibiaxialRoundOff);
  // A probe on the far side sees nothing.
  EXPECT_EQ(membrane_compression(ref, x, law, south, 0.3).min_tension_near_probe, 0.0);
}
