#include "capsflow/core/stepping/rkc2.hpp"

#include <utility>

namespace capsflow {

Rkc2::Rkc2(Options opt) : StabilizedStepper(opt, RkcCoefficients::stability_interval(opt.max_stages)) {}

// Y_1 = Y_0 + μ̃_1 τ F(Y_0), then the three-term recurrence (rkc_coefficients.hpp); y_{n+1} = Y_s.
long Rkc2::stages(RightHandSide& f, double tau, int s) {
  if (k_.stages != s) k_ = RkcCoefficients::make(s);
  const RkcCoefficients& k = k_;
  long evaluations = 0;
  yjm2_ = y0_;
  yjm1_.noalias() = y0_ + (k.mu_t[1] * tau) * f0_;
  if (opt_.predict_stages && s >= 4) y1_ = yjm1_;
  for (int j = 2; j <= s; ++j) {
    f.evaluate(yjm1_, fj_, stage_hint(j - 1, yjm1_, s));
    ++evaluations;
    yj_.noalias() = (1 - k.mu[j] - k.nu[j]) * y0_ + k.mu[j] * yjm1_ + k.nu[j] * yjm2_ +
                    (k.mu_t[j] * tau) * fj_ + (k.gamma_t[j] * tau) * f0_;
    std::swap(yjm2_, yjm1_);
    std::swap(yjm1_, yj_);
  }
  // yjm1_ = Y_s = y_{n+1}; its velocity is the next step's F_n.
  if (opt_.project && yjm1_.allFinite()) opt_.project(yjm1_);
  f.evaluate(yjm1_, f1_, stage_hint(s, yjm1_, s));
  ++evaluations;
  if (opt_.error_control) est_.noalias() = (12.0 / 15.0) * (y0_ - yjm1_) + (6.0 * tau / 15.0) * (f0_ + f1_);
  return evaluations;
}

}  // namespace capsflow
