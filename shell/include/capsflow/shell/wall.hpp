#pragma once
// Abstract capsule wall used by the time integrator, and the membrane-only wall.
//
// forces(x, R_s): nodal internal forces R_s = dE/dx at node positions x. For a GSMB wall the
// rotations are first brought to equilibrium, R_theta(x, theta) = 0 (warm start from the
// previous directors), so R_s is the total derivative of the wall energy. The load per deformed
// area is q from M(x) q = R_s (see load_recovery.hpp); with v = v_inf - S[q] a pre-inflated
// capsule shrinks (R_s, q point outward when the wall is stretched).
#include <Eigen/Core>
#include <array>
#include <vector>

#include "capsflow/shell/element.hpp"
#include "capsflow/shell/laws.hpp"
#include "capsflow/shell/topology.hpp"
#include "capsflow/shell/types.hpp"

namespace capsflow::shell {

class Wall {
 public:
  virtual ~Wall() = default;
  virtual void forces(const Points& x, Points& R_s, WallStats* stats = nullptr) = 0;
  virtual WallEnergies energies(const Points& x) const = 0;  ///< at the current directors
  /// Nodal energy maps, paper Eq. (54)-(56): at node i, (sum over the elements e around i of the
  /// element energy) / (sum of their reference areas), i.e. energy per reference area. The bending
  /// and shear maps use the energy densities (h^3/24) C chi chi and (h/2) D zeta zeta (the 1/2 of a
  /// quadratic energy; the paper's printed Eq. 55-56 omit it), so Eb/Em is a true energy ratio.
  virtual void nodal_energy_maps(const Points& x, Eigen::VectorXd& Em, Eigen::VectorXd& Eb,
                                 Eigen::VectorXd& Esh) const = 0;
  /// Everything needed to restart bit-for-bit (GSMB: directors and triads; membrane: empty).
  virtual Eigen::VectorXd state() const = 0;
  virtual void set_state(const Eigen::VectorXd&) = 0;
  /// Forget the warm start: the next forces() solves the rotations from the nodal normals of x
  /// (for a stage state far from the previous one, where the warm start can defeat Newton).
  virtual void restart_rotations(const Points& x) { (void)x; }

  /// Where the next forces() starts its rotation solve, told by the time scheme (the stage
  /// predictor, docs/shell.md §2.4): solutions are kept in a few slots, and a stage whose state is
  /// ≈ Σ weight_k × (the state of slot_k) starts from the same combination of their solutions.
  /// Applies to the next forces() only; walls without rotations ignore it.
  struct WarmStart {
    static constexpr int kSlots = 4, kTerms = 4;
    int keep_start = -1;  ///< before solving, keep the solution it would start from (the last call's) here
    int keep = -1;        ///< after solving, keep this call's solution here
    int terms = 0;        ///< 0: start from the last call's solution (the default)
    std::array<int, kTerms> slot{};
    std::array<double, kTerms> weight{};  ///< Σ weight = 1
  };
  virtual void set_warm_start(const WarmStart& w) { (void)w; }
};

/// Membrane-only wall (paper §2.3.3): no rotations; R_s = d/dx sum_e A0 W_s.
class MembraneWall : public Wall {
 public:
  MembraneWall(const Points& X_ref, const Triangles& tri, MembraneLaw law);
  void forces(const Points& x, Points& R_s, WallStats* stats = nullptr) override;
  WallEnergies energies(const Points& x) const override;
  void nodal_energy_maps(const Points& x, Eigen::VectorXd& Em, Eigen::VectorXd& Eb,
                         Eigen::VectorXd& Esh) const override;
  Eigen::VectorXd state() const override { return {}; }
  void set_state(const Eigen::VectorXd&) override {}
  const MembraneLaw& law() const { return law_; }
  const Topology& topology() const { return topo_; }

 private:
  MembraneLaw law_;
  Topology topo_;
  std::vector<MembraneRef> ref_;
  struct ElementForces { Vec3 f[3]; };  // one element's nodal forces (forces())
  std::vector<ElementForces> fe_;
  mutable std::vector<double> partial_;
};

/// Nodal average of element values (helper for the energy maps): out_i = sum_e v_e / sum_e A_e.
void nodal_average(const Topology& topo, const std::vector<double>& elem_value,
                   const std::vector<double>& elem_area, Eigen::VectorXd& out);

}  // namespace capsflow::shell
