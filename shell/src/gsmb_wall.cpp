#include "capsflow/shell/gsmb_wall.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "capsflow/shell/director.hpp"
#include "capsflow/shell/parallel.hpp"
#include "capsflow/shell/parallel_thresholds.hpp"

namespace capsflow::shell {

namespace {
// A healthy step with the frozen tangent divides the residual by 50–1000; one that divides it by less
// than 2 has a stale tangent.
constexpr double kStaleTangent = 0.5;
// The geometric part of the tangent, −(g·d) per node, is floored at −(a floor) × the smaller material
// diagonal entry so that the diagonal stays positive far from equilibrium. A solve starts at
// kGeometricFloor; if CG then meets negative curvature and cannot move (the tangent is indefinite), it
// falls back to kSafeGeometricFloor for the rest of the solve; a solve that fails even so starts again
// at kSafeGeometricFloor throughout (solve_rotations). Both floors are needed: docs/shell.md §2.4.
constexpr double kGeometricFloor = 0.9, kSafeGeometricFloor = 0.5;
// CG stalled: its relative residual is still above this after the solve.
constexpr double kStalledCg = 0.5;
// The pass's loops hand out elements and nodes in chunks of this many: with equal static halves the
// two halves did not take equal time (the wall phase at 81 920 elements: cpu/wall 1.71 against 1.80
// in chunks; perf/RESULTS.md §1.1). Every iteration writes only its own record and the only
// reduction is a maximum, so the results do not depend on which thread took which chunk.
constexpr int kPassChunk = 256;
}  // namespace

GsmbWall::GsmbWall(const Points& X, const Triangles& tri, MembraneLaw law, GsmbOptions opt)
    : law_(law), opt_(opt), topo_(tri, X.rows()) {
  init(X, area_weighted_normals(X, tri));
}

GsmbWall::GsmbWall(const Points& X, const Triangles& tri, const Points& D, MembraneLaw law,
                   GsmbOptions opt)
    : law_(law), opt_(opt), topo_(tri, X.rows()) {
  if (D.rows() != X.rows()) throw std::invalid_argument("GsmbWall: D_ref must have one row per node");
  Points Dn = D;
  for (Eigen::Index i = 0; i < Dn.rows(); ++i) Dn.row(i).normalize();
  init(X, Dn);
}

void GsmbWall::init(const Points& X, const Points& D) {
  if (!(opt_.thickness > 0)) throw std::invalid_argument("GsmbWall: thickness must be > 0");
  const int n = topo_.n_nodes;
  D_ = D;
  const double G = law_.Gs() / opt_.thickness;
  ref_.resize(topo_.n_elems);
  for (int e = 0; e < topo_.n_elems; ++e) {
    const auto& t = topo_.tri[e];
    const Vec3 Xe[3] = {X.row(t[0]), X.row(t[1]), X.row(t[2])};
    const Vec3 De[3] = {D.row(t[0]), D.row(t[1]), D.row(t[2])};
    ref_[e] = make_element_ref(Xe, De, t, opt_.thickness, G, opt_.poisson);
  }
  set_directors(D_);
  area_weighted_normals(X, topo_, n_prev_);
  n_cur_ = n_prev_;
  fx_.setZero(n, 3);
  g_.setZero(n, 3);
  Rth_.setZero(2 * n);
  dw_.setZero(2 * n);
  kdiag_.setZero(2 * n);
  // theta-theta pattern: 2x2 blocks on the node adjacency
  row_base_.resize(n);
  row_len2_.resize(n);
  std::vector<Eigen::Triplet<double, int>> trip;
  trip.reserve(static_cast<size_t>(topo_.nnz_nodes()) * 4);
  for (int i = 0; i < n; ++i) {
    row_base_[i] = 4 * topo_.adj_ptr[i];
    row_len2_[i] = 2 * (topo_.adj_ptr[i + 1] - topo_.adj_ptr[i]);
    for (int k = 0; k < 2; ++k)
      for (int p = topo_.adj_ptr[i]; p < topo_.adj_ptr[i + 1]; ++p)
        for (int l = 0; l < 2; ++l) trip.emplace_back(2 * i + k, 2 * topo_.adj[p] + l, 0.0);
  }
  K_.resize(2 * n, 2 * n);
  K_.setFromTriplets(trip.begin(), trip.end());
  K_.makeCompressed();
  for (int i = 0; i < n; ++i)
    if (K_.outerIndexPtr()[2 * i] != row_base_[i] ||
        K_.outerIndexPtr()[2 * i + 1] != row_base_[i] + row_len2_[i])
      throw std::logic_error("GsmbWall: unexpected sparsity layout");
}

void GsmbWall::set_directors(const Points& d) { triads_ = NodalTriads(d); }

void GsmbWall::rotate(const Eigen::VectorXd& w) {
  const int n = topo_.n_nodes;
#pragma omp parallel for schedule(static) if (n > kParallelNodes)
  for (int i = 0; i < n; ++i)
    triads_.rotate(i, w[2 * i] * Vec3(triads_.t1.row(i)) + w[2 * i + 1] * Vec3(triads_.t2.row(i)));
}

void GsmbWall::evaluate(const Points& x, Points* fx, Eigen::VectorXd* R_theta, bool want_K,
                        bool want_fx) {
  if (x.rows() != topo_.n_nodes) throw std::invalid_argument("GsmbWall: x has the wrong number of rows");
  pass(x, Prologue::None, want_K, want_fx);
  if (fx) *fx = fx_;
  if (R_theta) *R_theta = Rth_;
}

double GsmbWall::pass(const Points& x, Prologue prologue, bool want_K, bool want_fx) {
  const int n = topo_.n_nodes, ne = topo_.n_elems;
  // One team for the whole pass, with one barrier: every element writes its nodal contributions to
  // its own record (any thread count, any order), then every node sums its elements' records in the
  // order of their colours — the order in which the colour-by-colour assembly added them, so the
  // sums are those of a serial pass for any thread count. A node-wise prologue (the predictor, or
  // the Newton step) runs in the same team before the elements.
  eout_.resize(ne);
  if (prologue == Prologue::Predict && start_.size() != n) start_ = triads_;
  const bool from_kept = prologue == Prologue::Predict && kept_usable();  // the stage predictor
  double* Kv = K_.valuePtr();
  par::TeamBarrier barrier;
  const bool team = ne > kParallelGsmbPass;
  const int max_team = team ? omp_get_max_threads() : 1;
  if (static_cast<int>(thread_max_.size()) < max_team) thread_max_.resize(max_team);
  int used = 1;  // threads of the team
#pragma omp parallel if (team)
  {
    const int T = omp_get_num_threads(), tid = omp_get_thread_num();
    if (tid == 0) used = T;
    if (prologue == Prologue::Predict) {
      // Each triad turned by the smallest rotation from its node's normal at the last solve to the
      // current one; then the start of the solve is kept (a failed solve starts again from it).
#pragma omp for schedule(dynamic, kPassChunk) nowait
      for (int i = 0; i < n; ++i) {
        const Vec3 nc = area_weighted_normal(x, topo_, i);
        n_cur_.row(i) = nc.transpose();
        Vec3 w;
        if (from_kept)
          predict_from_kept(i, nc);
        else if (minimal_rotation(Vec3(n_prev_.row(i)), nc, w))
          triads_.rotate(i, w);
        n_prev_.row(i) = n_cur_.row(i);
        start_.d.row(i) = triads_.d.row(i);
        start_.t1.row(i) = triads_.t1.row(i);
        start_.t2.row(i) = triads_.t2.row(i);
      }
      barrier.wait(T);
    } else if (prologue == Prologue::Step) {
      // The Newton increment dw_, scaled down if a nodal rotation exceeds max_step.
      double big = 0;
#pragma omp for schedule(dynamic, kPassChunk) nowait
      for (int i = 0; i < n; ++i) big = std::max(big, std::hypot(dw_[2 * i], dw_[2 * i + 1]));
      thread_max_[tid] = big;
      barrier.wait(T);
      for (int t = 0; t < T; ++t) big = std::max(big, thread_max_[t]);
      const double scale = big > opt_.max_step ? opt_.max_step / big : 1.0;
#pragma omp for schedule(dynamic, kPassChunk) nowait
      for (int i = 0; i < n; ++i) {
        const double w1 = big > opt_.max_step ? dw_[2 * i] * scale : dw_[2 * i];
        const double w2 = big > opt_.max_step ? dw_[2 * i + 1] * scale : dw_[2 * i + 1];
        triads_.rotate(i, w1 * Vec3(triads_.t1.row(i)) + w2 * Vec3(triads_.t2.row(i)));
      }
      barrier.wait(T);
    }
#pragma omp for schedule(dynamic, kPassChunk) nowait
    for (int e = 0; e < ne; ++e) {
      const ElementRef& R = ref_[e];
      const auto& nd = R.m.n;
      Vec3 xe[3], de[3], T[3][2];
      for (int a = 0; a < 3; ++a) {
        const int i = nd[a];
        xe[a] = x.row(i);
        de[a] = triads_.d.row(i);
        T[a][0] = -triads_.t2.row(i);
        T[a][1] = triads_.t1.row(i);
      }
      BsOut o;
      bs_element(R, xe, de, T, o, want_K);
      ElementOut& out = eout_[e];
      if (want_fx) {
        Vec3 fm[3];
        membrane_element(R.m, law_, xe, fm, false);
        for (int a = 0; a < 3; ++a)
          for (int c = 0; c < 3; ++c) out.f[a][c] = fm[a][c] + o.fx[a][c];
      }
      for (int a = 0; a < 3; ++a)
        for (int c = 0; c < 3; ++c) out.f[a][3 + c] = o.g[a][c];
      if (want_K)
        for (int r = 0; r < 6; ++r)
          for (int c = 0; c < 6; ++c) out.K[r][c] = o.K[r][c];
    }
    barrier.wait(T);
    // per node: forces, director forces, tangent rows, residual and geometric term, and the
    // largest |R_theta|/K_ii (the Newton criterion; a maximum: the same for any split)
    double res = 0;
#pragma omp for schedule(dynamic, kPassChunk) nowait
    for (int i = 0; i < n; ++i) {
      double acc[6] = {0, 0, 0, 0, 0, 0};
      const int p0 = topo_.inc_ptr[i], p1 = topo_.inc_ptr[i + 1];
      for (int p = p0; p < p1; ++p) {
        const double* f = eout_[topo_.inc_elem_by_colour[p]].f[topo_.inc_local_by_colour[p]];
        if (want_fx)
          for (int c = 0; c < 3; ++c) acc[c] += f[c];
        for (int c = 3; c < 6; ++c) acc[c] += f[c];
      }
      for (int c = 0; c < 3; ++c) {
        fx_(i, c) = acc[c];
        g_(i, c) = acc[3 + c];
      }
      if (want_K) {
        double* row0 = Kv + row_base_[i];
        std::fill(row0, row0 + 2 * row_len2_[i], 0.0);
        for (int p = p0; p < p1; ++p) {
          const int e = topo_.inc_elem_by_colour[p], a = topo_.inc_local_by_colour[p];
          const auto& pp = topo_.pair_pos[e];
          const ElementOut& out = eout_[e];
          for (int b = 0; b < 3; ++b) {
            const int pos = 2 * pp[a * 3 + b];
            for (int kk = 0; kk < 2; ++kk) {
              double* rowp = row0 + kk * row_len2_[i] + pos;
              rowp[0] += out.K[2 * a + kk][2 * b];
              rowp[1] += out.K[2 * a + kk][2 * b + 1];
            }
          }
        }
      }
      // nodal residual and geometric term
      const Vec3 gi = g_.row(i);
      Rth_[2 * i] = -triads_.t2.row(i).dot(gi);
      Rth_[2 * i + 1] = triads_.t1.row(i).dot(gi);
      if (want_K) {
        const int dp = row_base_[i] + 2 * topo_.diag_pos[i];
        if (opt_.geometric_tangent) {
          // exact second-order term of the exponential map, floored (geometric_floor_)
          const double kmin = std::min(Kv[dp], Kv[dp + row_len2_[i] + 1]);
          const double c = std::max(-gi.dot(triads_.d.row(i)), -geometric_floor_ * kmin);
          Kv[dp] += c;
          Kv[dp + row_len2_[i] + 1] += c;
        }
        kdiag_[2 * i] = Kv[dp];
        kdiag_[2 * i + 1] = Kv[dp + row_len2_[i] + 1];
      }
      res = std::max(res, std::abs(Rth_[2 * i]) / kdiag_[2 * i]);
      res = std::max(res, std::abs(Rth_[2 * i + 1]) / kdiag_[2 * i + 1]);
    }
    thread_max_[tid] = res;
  }
  double res = 0;
  for (int t = 0; t < used; ++t) res = std::max(res, thread_max_[t]);
  return res;
}

bool GsmbWall::kept_usable() const {
  if (warm_.terms <= 0 || warm_.terms > WarmStart::kTerms) return false;
  for (int k = 0; k < warm_.terms; ++k) {
    const int s = warm_.slot[k];
    if (s < 0 || s >= WarmStart::kSlots || kept_d_[s].rows() != topo_.n_nodes) return false;
  }
  return true;
}

void GsmbWall::predict_from_kept(int i, const Vec3& nc) {
  // Each kept director carried by its node's normal from that solve to this state (the default
  // predictor applied to the slot), then combined with the scheme's weights.
  Vec3 d = Vec3::Zero(), w;
  for (int k = 0; k < warm_.terms; ++k) {
    const int s = warm_.slot[k];
    Vec3 dk = kept_d_[s].row(i);
    if (minimal_rotation(Vec3(kept_n_[s].row(i)), nc, w)) dk = rodrigues(w, dk);
    d += warm_.weight[k] * dk;
  }
  if (d.squaredNorm() > 0 && minimal_rotation(Vec3(triads_.d.row(i)), d.normalized(), w)) triads_.rotate(i, w);
}

WallStats GsmbWall::solve_rotations(const Points& x) {
  WallStats st;
  if (warm_.keep_start >= 0 && warm_.keep_start < WarmStart::kSlots) {
    kept_d_[warm_.keep_start] = triads_.d;  // the last solve and its normals
    kept_n_[warm_.keep_start] = n_prev_;
  }
  // The predictor runs in the first element pass (pass(), Prologue::Predict), which also keeps
  // the predicted triads in start_.
  if (!opt_.predict) start_ = triads_;
  newton(x, kGeometricFloor, st, opt_.predict ? Prologue::Predict : Prologue::None);
  if (!st.converged) {
    // Failure path only (converged solves never come here, so they are unchanged): start again from
    // the predicted triads with the safer floor throughout (docs/shell.md §2.4).
    triads_ = start_;
    st.converged = true;
    newton(x, kSafeGeometricFloor, st, Prologue::None);
  }
  last_newton_ = st.newton_iterations;
  if (st.converged && opt_.predict && warm_.keep >= 0 && warm_.keep < WarmStart::kSlots) {
    kept_d_[warm_.keep] = triads_.d;
    kept_n_[warm_.keep] = n_prev_;  // the normals of this solve (the predictor set them)
  }
  warm_ = WarmStart{};
  return st;
}

void GsmbWall::newton(const Points& x, double floor, WallStats& st, Prologue first) {
  // The membrane force does not depend on the rotations: when the previous call needed a Newton
  // correction (the usual RK stage), the first pass skips it and computes only R_theta and K; the
  // x-forces come from the pass at the converged directors. Results do not depend on this choice.
  const bool lazy_fx = last_newton_ > 0;
  double previous = std::numeric_limits<double>::infinity();
  geometric_floor_ = floor;
  Prologue prologue = first;  // then Step: each Newton increment is applied by the next pass
  for (int it = 0;; ++it) {
    // tangent built at the first Newton step of each call and reused by the later steps of the
    // same call (they start within O(newton step^2) of the solution; the residual is exact)
    const bool want_fx = !(it == 0 && lazy_fx);
    const double res = pass(x, prologue, it == 0, want_fx);
    if (it > 0 && res > opt_.newton_tol && res > kStaleTangent * previous) {
      // The frozen tangent no longer contracts: the iterate has moved far from where it was built,
      // as when it leaves a saddle (docs/shell.md §2.4). Rebuild it at this iterate; with a
      // tangent frozen at the saddle the escape ends in a 2-cycle at residual 0.2 (measured).
      pass(x, Prologue::None, true, want_fx);
    }
    previous = res;
    st.residual = res;
    if (res <= opt_.newton_tol && !want_fx) pass(x, Prologue::None, false, true);
    if (res <= opt_.newton_tol || it >= opt_.max_newton) {
      if (res > opt_.newton_tol) st.converged = false;
      if (trace_) trace_({it, res, geometric_floor_, 0, 0.0});
      break;
    }
    Rth_ = -Rth_;
    double rr = 0;
    int cg = pcg_.solve(K_, Rth_.data(), dw_.data(), opt_.cg_tol, opt_.max_cg, &rr);
    if (rr > kStalledCg && geometric_floor_ > kSafeGeometricFloor) {
      // Negative curvature stopped CG: an indefinite tangent. Rebuild it with the safer floor.
      geometric_floor_ = kSafeGeometricFloor;
      pass(x, Prologue::None, true, want_fx);
      Rth_ = -Rth_;
      cg += pcg_.solve(K_, Rth_.data(), dw_.data(), opt_.cg_tol, opt_.max_cg, &rr);
    }
    st.cg_iterations += cg;
    if (trace_) trace_({it, res, geometric_floor_, cg, rr});
    prologue = Prologue::Step;  // the next pass applies dw_ (scaled to max_step) first
    ++st.newton_iterations;
  }
}

void GsmbWall::restart_rotations(const Points& x) {
  area_weighted_normals(x, topo_, n_cur_);
  set_directors(n_cur_);
  n_prev_ = n_cur_;
  last_newton_ = 0;
}

void GsmbWall::forces(const Points& x, Points& R_s, WallStats* stats) {
  if (&R_s == &x) throw std::invalid_argument("GsmbWall::forces: R_s must not alias x");
  const WallStats st = solve_rotations(x);
  if (R_s.rows() != x.rows()) R_s.resize(x.rows(), 3);
  R_s = fx_;
  if (stats) *stats = st;
}

void GsmbWall::element_energies(const Points& x, std::vector<double>* em, std::vector<double>* eb,
                                std::vector<double>* es) const {
  const int ne = topo_.n_elems;
#pragma omp parallel for schedule(static)
  for (int e = 0; e < ne; ++e) {
    const ElementRef& R = ref_[e];
    const auto& nd = R.m.n;
    const Vec3 xe[3] = {x.row(nd[0]), x.row(nd[1]), x.row(nd[2])};
    const Points& d = triads_.d;
    const Vec3 de[3] = {d.row(nd[0]), d.row(nd[1]), d.row(nd[2])};
    Vec3 fm[3];
    const Vec3 T[3][2] = {};
    BsOut o;
    const double wm = membrane_element(R.m, law_, xe, fm);
    bs_element(R, xe, de, T, o, false);
    (*em)[e] = wm;
    (*eb)[e] = o.Eb;
    (*es)[e] = o.Es;
  }
}

WallEnergies GsmbWall::energies(const Points& x) const {
  std::vector<double> em(topo_.n_elems), eb(topo_.n_elems), es(topo_.n_elems);
  element_energies(x, &em, &eb, &es);
  WallEnergies E;
  E.membrane = par::det_sum(topo_.n_elems, partial_, [&](long e) { return em[e]; });
  E.bending = par::det_sum(topo_.n_elems, partial_, [&](long e) { return eb[e]; });
  E.shear = par::det_sum(topo_.n_elems, partial_, [&](long e) { return es[e]; });
  return E;
}

void GsmbWall::nodal_energy_maps(const Points& x, Eigen::VectorXd& Em, Eigen::VectorXd& Eb,
                                 Eigen::VectorXd& Esh) const {
  std::vector<double> em(topo_.n_elems), eb(topo_.n_elems), es(topo_.n_elems), A(topo_.n_elems);
  element_energies(x, &em, &eb, &es);
  for (int e = 0; e < topo_.n_elems; ++e) A[e] = ref_[e].m.A0;
  nodal_average(topo_, em, A, Em);
  nodal_average(topo_, eb, A, Eb);
  nodal_average(topo_, es, A, Esh);
}

Eigen::VectorXd GsmbWall::state() const {
  const int n = topo_.n_nodes;
  Eigen::VectorXd s(12 * n);
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) {
      s[3 * i + k] = triads_.d(i, k);
      s[3 * n + 3 * i + k] = triads_.t1(i, k);
      s[6 * n + 3 * i + k] = triads_.t2(i, k);
      s[9 * n + 3 * i + k] = n_prev_(i, k);
    }
  return s;
}

void GsmbWall::set_state(const Eigen::VectorXd& s) {
  const int n = topo_.n_nodes;
  if (s.size() != 12 * n) throw std::invalid_argument("GsmbWall::set_state: wrong size");
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) {
      triads_.d(i, k) = s[3 * i + k];
      triads_.t1(i, k) = s[3 * n + 3 * i + k];
      triads_.t2(i, k) = s[6 * n + 3 * i + k];
      n_prev_(i, k) = s[9 * n + 3 * i + k];
    }
}

}  // namespace capsflow::shell
