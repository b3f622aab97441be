#include "capsflow/core/stepping/rock4.hpp"

#include <algorithm>
#include <utility>

namespace capsflow {

Rock4::Rock4(Options opt)
    : StabilizedStepper(opt, Rock4Coefficients::stability_interval(std::min(opt.max_stages, Rock4Coefficients::max_stages()))) {}

// ROCK4's finishing stages lie within a short step of u_1 = g_{s−4}: predicted from Y_0, Y_1,
// g_{s−5} and u_1 (whose evaluation kept its solution), none of them kept.
EvaluationHint Rock4::finishing_hint(int m, const Points& y, int base) const {
  EvaluationHint h{EvaluationHint::Role::Trajectory, m};
  if (!opt_.predict_stages || base < 3) return h;  // Y_1 and g_{s−5} distinct
  const Points* states[StagePredictor::kTerms] = {&y0_, &y1_, &yjm2_, &yjm1_};  // yjm2_ = g_{s−5}, yjm1_ = u_1
  const int slots[StagePredictor::kTerms] = {0, 1, 2 + (base - 1) % 2, 2 + base % 2};
  predict_stage(h.predictor, y, states, slots, 4);
  return h;
}

long Rock4::stages(RightHandSide& f, double tau, int s) {
  if (k_.stages != s) k_ = Rock4Coefficients::make(s);
  const Rock4Coefficients& k = k_;
  long evaluations = 0;
  // Recurrence part: g_0 = y_n, g_1 = g_0 + μ_1 τ F(g_0), g_j = μ_j τ F(g_{j−1}) − ν_j g_{j−1} − κ_j g_{j−2}.
  // Its stages g_j are predicted as RKC2's are (the same three-term shape), and so is u_1 = g_{s−4};
  // the finishing stages, within a short step of u_1, from finishing_hint.
  const int base = s - 4;
  yjm2_ = y0_;
  yjm1_.noalias() = y0_ + (k.mu[1] * tau) * f0_;
  if (opt_.predict_stages) y1_ = yjm1_;
  for (int j = 2; j <= base; ++j) {
    f.evaluate(yjm1_, fj_, stage_hint(j - 1, yjm1_, base));
    ++evaluations;
    yj_.noalias() = (k.mu[j] * tau) * fj_ - k.nu[j] * yjm1_ - k.kappa[j] * yjm2_;
    std::swap(yjm2_, yjm1_);
    std::swap(yjm1_, yj_);
  }
  // Finishing method from u_1 = g_{s−4} (in yjm1_; yjm2_ and yj_ are free).
  const Points& u1 = yjm1_;
  f.evaluate(u1, kw_[0], stage_hint(base, u1, base + 1));
  Points& u = yj_;  // free once u_1's prediction has used it
  u.noalias() = u1 + (k.a[0] * tau) * kw_[0];
  f.evaluate(u, kw_[1], finishing_hint(base + 1, u, base));
  u.noalias() = u1 + (k.a[1] * tau) * kw_[0] + (k.a[2] * tau) * kw_[1];
  f.evaluate(u, kw_[2], finishing_hint(base + 2, u, base));
  u.noalias() = u1 + (k.a[3] * tau) * kw_[0] + (k.a[4] * tau) * kw_[1] + (k.a[5] * tau) * kw_[2];
  f.evaluate(u, kw_[3], finishing_hint(base + 3, u, base));
  evaluations += 4;
  yjm2_.noalias() = u1 + tau * (k.b[0] * kw_[0] + k.b[1] * kw_[1] + k.b[2] * kw_[2] + k.b[3] * kw_[3]);
  std::swap(yjm1_, yjm2_);  // yjm1_ = y_{n+1}
  if (opt_.project && yjm1_.allFinite()) opt_.project(yjm1_);
  f.evaluate(yjm1_, f1_, {EvaluationHint::Role::Trajectory, s});
  ++evaluations;
  if (opt_.error_control)
    est_.noalias() = tau * ((k.b[0] - k.bhat[0]) * kw_[0] + (k.b[1] - k.bhat[1]) * kw_[1] + (k.b[2] - k.bhat[2]) * kw_[2] +
                            (k.b[3] - k.bhat[3]) * kw_[3] - k.bhat[4] * f1_);
  return evaluations;
}

}  // namespace capsflow
