#include "capsflow/core/rhs/capsule_dynamics.hpp"

#include <fmt/core.h>

#include <nlohmann/json.hpp>

#include "capsflow/core/geometry/measures.hpp"
#include "capsflow/core/rhs/volume_constraint.hpp"
#include "capsflow/core/scene/boundary_integral_options.hpp"

namespace capsflow {

CapsuleDynamics::CapsuleDynamics(const Scene& scene, const SurfaceMesh& reference, int threads,
                                 std::unique_ptr<shell::Wall> wall)
    : L_(scene.flow.gradient),
      volume_correction_(scene.fluid.volume_correction),
      tri_(reference.triangles),
      n_nodes_(reference.num_nodes()),
      wall_load_(scene, reference, std::move(wall)),
      bie_(reference.triangles, reference.num_nodes(), boundary_integral_options(scene, threads)) {
  if (scene.fluid.viscosity_ratio != 1.0) {
    GmresOptions go;
    go.tolerance = scene.fluid.tolerance;  // the far field's promise, relative to the velocity (§4.8.3)
    go.max_iterations = scene.fluid.max_gmres;
    viscosity_ = std::make_unique<ViscosityRatioSolver>(reference.triangles, reference.num_nodes(),
                                                        scene.fluid.viscosity_ratio, double_layer_options(scene, threads), go);
  }
}

PhaseTimes CapsuleDynamics::times() const {
  PhaseTimes t = times_;
  t += bie_.times();
  if (viscosity_) {  // the double layer's direct checks (fluid.verify_every) move from the solve to bie_verify
    const PhaseTimes& d = viscosity_->double_layer().times();
    t[Phase::BieSecondKind] -= d[Phase::BieVerify], t.cpu(Phase::BieSecondKind) -= d.cpu(Phase::BieVerify);
    t[Phase::BieVerify] += d[Phase::BieVerify], t.cpu(Phase::BieVerify) += d.cpu(Phase::BieVerify);
  }
  return t;
}

void CapsuleDynamics::solve_wall(const Points& x, const EvaluationHint& hint) {
  Stopwatch clock;
  wall_load_.solve(x, hint, counters_, times_, clock);
  ++counters_.wall_solves;
}

CapsuleDynamics::Carry CapsuleDynamics::carry() const {
  return {{wall_load_.wall().state()}, wall_load_.load(),
          viscosity_ ? viscosity_->warm_start() : ViscosityRatioSolver::WarmStart{}, Points{}};
}

void CapsuleDynamics::restore(Carry c) {
  wall_load_.wall().set_state(c.walls.at(0));
  wall_load_.set_load(std::move(c.load));
  if (viscosity_) viscosity_->set_warm_start(std::move(c.viscosity));
}

namespace {
constexpr Eigen::Index kWarmStartColumns = 9, kIdentityRecordColumns = 24;  // per node
using NodeRows = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
}  // namespace

void CapsuleDynamics::save_fluid_state(nlohmann::json& extra, Eigen::MatrixXd& matrix) const {
  matrix.resize(0, 0);
  if (!viscosity_) return;
  const ViscosityRatioSolver::WarmStart w = viscosity_->warm_start();
  const DoubleLayer& D = viscosity_->double_layer();
  const std::vector<double>& records = D.identity_records();
  const Eigen::Index n = n_nodes_;
  const bool warm = w.valid && w.y.size() == 3 * n && w.b.size() == 3 * n && w.residual.size() == 3 * n;
  const int count = static_cast<Eigen::Index>(records.size()) == kIdentityRecordColumns * n ? D.identity_record_count() : 0;
  extra["fluid_state"] = {{"warm_start", warm}, {"identity_records", count}};
  const Eigen::Index cols = (warm ? kWarmStartColumns : 0) + (count > 0 ? kIdentityRecordColumns : 0);
  matrix.resize(cols > 0 ? n : 0, cols);
  Eigen::Index c = 0;
  if (warm)
    for (const Eigen::VectorXd* v : {&w.y, &w.b, &w.residual}) matrix.middleCols(c, 3) = Points::Map(v->data(), n, 3), c += 3;
  if (count > 0) matrix.middleCols(c, kIdentityRecordColumns) = NodeRows::Map(records.data(), n, kIdentityRecordColumns);
}

void CapsuleDynamics::load_fluid_state(const nlohmann::json& extra, const Eigen::MatrixXd& matrix) {
  if (!viscosity_ || !extra.contains("fluid_state")) return;
  const nlohmann::json& f = extra.at("fluid_state");
  const bool warm = f.at("warm_start").get<bool>();
  const int count = f.at("identity_records").get<int>();
  const Eigen::Index n = n_nodes_;
  const Eigen::Index cols = (warm ? kWarmStartColumns : 0) + (count > 0 ? kIdentityRecordColumns : 0);
  if (cols == 0 || matrix.rows() != n || matrix.cols() != cols) return;
  Eigen::Index c = 0;
  if (warm) {
    ViscosityRatioSolver::WarmStart w;
    for (Eigen::VectorXd* v : {&w.y, &w.b, &w.residual}) {
      v->resize(3 * n);
      Points::Map(v->data(), n, 3) = matrix.middleCols(c, 3), c += 3;
    }
    w.valid = true;
    viscosity_->set_warm_start(std::move(w));
  }
  if (count > 0) {
    std::vector<double> records(static_cast<size_t>(kIdentityRecordColumns * n));
    NodeRows::Map(records.data(), n, kIdentityRecordColumns) = matrix.middleCols(c, kIdentityRecordColumns);
    viscosity_->set_identity_records(records, count);  // refused by another back end: D̃[1] refreshes afresh
  }
}

void CapsuleDynamics::evaluate(const Points& x, Points& v, const EvaluationHint& hint) {
  const bool probe = hint.role == EvaluationHint::Role::Probe;
  Stopwatch clock;
  wall_load_.solve(x, hint, counters_, times_, clock);

  bie_.apply(x, wall_load_.load(), u_);

  clock.restart();
  // v = v∞ − S[q] (paper Eq. 34), the imposed flow taken relative to the capsule's centroid c:
  // v∞ = L (x − c). A uniform velocity changes neither the load nor the disturbance of a capsule in
  // a linear unbounded flow, so the shape is the lab frame's; but the centroid no longer drifts
  // with L c, which in a strain makes any asymmetry grow like e^{γ̇t} (docs/conventions.md §3.1).
  const Vec3 c = volume_moments(x, tri_).centroid;
  v.noalias() = (x.rowwise() - c.transpose()) * L_.transpose() - u_;
  if (viscosity_ || volume_correction_) volume_gradient(x, tri_, nodal_area_normal_);
  if (viscosity_) {  // λ ≠ 1: v∞ − S[q] is the right-hand side of the second-kind equation
    clock.lap(times_, Phase::Other);
    const bool on_trajectory = hint.role == EvaluationHint::Role::Trajectory;
    ViscosityRatioSolver::Prediction prediction;  // the stage predictor's, as the rotation solve has it
    static_assert(ViscosityRatioSolver::Prediction::kSlots == StagePredictor::kSlots &&
                  ViscosityRatioSolver::Prediction::kTerms == StagePredictor::kTerms);
    if (on_trajectory) {
      const StagePredictor& p = hint.predictor;
      prediction.keep_start = p.keep_start, prediction.keep = p.keep, prediction.terms = p.terms;
      prediction.slot = p.slot, prediction.weight = p.weight;
    }
    const ViscosityRatioStats st = viscosity_->solve(x, nodal_area_normal_, v, w_, probe, on_trajectory, prediction);
    clock.lap(times_, Phase::BieSecondKind);
    counters_.gmres_iterations += st.iterations;
    counters_.by_kind[static_cast<std::size_t>(evaluation_kind(hint))].gmres_iterations += st.iterations;
    if (!st.converged)
      throw SolverFailure(fmt::format("viscosity-ratio GMRES did not converge (relative residual {:.1e} after {} "
                                      "iterations)", st.residual, st.iterations));
    v.swap(w_);
  }
  if (volume_correction_) remove_normal_flux(nodal_area_normal_, v);
  clock.lap(times_, Phase::Other);
  ++counters_.evaluations;
  if (!v.allFinite()) throw SolverFailure("non-finite velocity");
}


}  // namespace capsflow
