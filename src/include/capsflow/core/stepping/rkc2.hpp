#pragma once
// Damped second-order Runge–Kutta–Chebyshev (RKC2) with local error control
// (docs/time-integration.md §5.6): the scheme "auto" picks where the wall is stiff for its mesh,
// since its stability interval covers about 1.86× more of τρ per stage² than ROCK4's (0.65 s²
// against 0.35 s²). The stages are RkcCoefficients' (stepping/rkc_coefficients.hpp); ρ, the
// controller, dense output and checkpoints are the shared StabilizedStepper's.
//
// Error estimate (Sommeijer et al. 1998): Est = [12 (y_n − y_{n+1}) + 6 τ (F_n + F_{n+1})] / 15,
// local error O(τ³): the controller's exponent 1/3.
//
// Why RKC2 and not ROCK2: both have stability intervals growing like s² (0.65 s² and 0.81 s²);
// RKC2's coefficients are closed-form (no stored tables), it has a free embedded error estimate,
// and the capsule Jacobian's spectrum is real up to the O(γ̇) flow terms, where ROCK2's better
// damping of imaginary parts buys nothing.
#include "capsflow/core/stepping/rkc_coefficients.hpp"
#include "capsflow/core/stepping/stabilized_stepper.hpp"

namespace capsflow {

class Rkc2 final : public StabilizedStepper {
 public:
  explicit Rkc2(Options opt);

 private:
  long stages(RightHandSide& f, double tau, int s) override;
  int stages_for(double tau_rho) const override { return RkcCoefficients::stages_for(tau_rho); }
  double estimate_order() const override { return 3.0; }
  const char* name() const override { return "rkc"; }

  RkcCoefficients k_;  // of the last step; rebuilt only when the stage count changes
};

}  // namespace capsflow
