#include "capsflow/core/bie/fixed_wall.hpp"

#include <fmt/core.h>

#include <chrono>
#include <stdexcept>
#include <vector>

#include "capsflow/core/bie/quadrature.hpp"
#include "capsflow/core/geometry/measures.hpp"
#include "capsflow/fmm/stokeslet.hpp"

namespace capsflow {
namespace {

Eigen::Map<Eigen::VectorXd> flat(Points& p) { return {p.data(), p.size()}; }

}  // namespace

FixedWall::FixedWall(const SurfaceMesh& wall, const Points& velocity, const FixedWallOptions& opt)
    : mesh_(wall), velocity_(velocity), opt_(opt) {
  const Eigen::Index n = wall.num_nodes();
  if (velocity.rows() != n) throw std::invalid_argument("fixed wall: one velocity per node is needed");
  if (opt.layer.geometry != SurfaceGeometry::Flat)
    throw std::invalid_argument("fixed wall: only flat facets (a wall's edges and corners have no vertex normal to lift by)");
  S_ = std::make_unique<SingleLayer>(wall.triangles, n, opt.layer);
  if (opt.reuse_operator) op_ = std::make_unique<FixedSingleLayer>(wall, opt.layer, opt.dense_operator_mb);
  area_ = nodal_areas(wall);
  normal_ = nodal_normals(wall);
  total_area_ = area_.sum();
  weight_.resize(3 * n);
  for (Eigen::Index i = 0; i < n; ++i) weight_.segment<3>(3 * i).setConstant(area_[i]);

  for (Eigen::Index e = 0; e < wall.num_elements(); ++e)
    for (int k = 0; k < 3; ++k)
      if (velocity_.row(wall.triangles(e, k)).squaredNorm() > 0) {
        moving_.push_back(e);
        break;
      }
  rhs0_ = Points::Zero(n, 3);
  if (!moving_.empty()) {  // a wall at rest (a channel's disturbance) has none
    DoubleLayerOptions dopt;
    static_cast<LayerOptions&>(dopt) = opt.layer;
    dopt.reuse_identity_term = false;  // one set-up: nothing to reuse
    DoubleLayer D(wall.triangles, n, dopt);
    Points Du;
    D.set_surface(wall.vertices, &velocity_, &Du);
    rhs0_ = 0.5 * velocity_ - Du;
  }
  traction_ = Points::Zero(n, 3);
  if (opt.edge_pressure) build_edge_pressure();
  if (opt.precondition) build_preconditioner();
}

void FixedWall::build_edge_pressure() {
  const SurfaceMesh& wall = mesh_;
  const Points ne = element_normals(wall);
  std::vector<Eigen::Index> column(static_cast<std::size_t>(wall.num_nodes()), -1);
  for (Eigen::Index e = 0; e < wall.num_elements(); ++e) {
    EdgeElement edge{e, {Vec3::Zero(), Vec3::Zero(), Vec3::Zero()}};
    bool any = false;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Index node = wall.triangles(e, k);
      const Vec3 dn = (ne.row(e) - normal_.row(node)).transpose();
      if (dn.norm() <= opt_.edge_angle) continue;
      edge.dn[static_cast<std::size_t>(k)] = dn;
      any = true;
      if (column[static_cast<std::size_t>(node)] < 0) {
        column[static_cast<std::size_t>(node)] = static_cast<Eigen::Index>(edge_nodes_.size());
        edge_nodes_.push_back(node);
      }
    }
    if (any) edge_elements_.push_back(edge);
  }
  // Column c: the flow at every node of a unit pressure at edge node c. A node of the element takes
  // its singular integral (closed form), any other node the adaptive rule.
  const Triangles& tri = wall.triangles;
  const Points& x = wall.vertices;
  edge_at_nodes_ = Eigen::MatrixXd::Zero(3 * wall.num_nodes(), static_cast<Eigen::Index>(edge_nodes_.size()));
#pragma omp parallel for schedule(dynamic, 16) num_threads(layer_threads(opt_.layer))
  for (Eigen::Index i = 0; i < wall.num_nodes(); ++i) {
    const Vec3 p = x.row(i).transpose();
    for (const EdgeElement& edge : edge_elements_) {
      int at = -1;  // the target's vertex position on this element
      for (int k = 0; k < 3; ++k)
        if (tri(edge.e, k) == i) at = k;
      std::array<Vec3, 3> flow;  // per vertex k: ∫ G φ_k dS (n_e − n_k), unscaled
      if (at >= 0) {
        const int a = (at + 1) % 3, b = (at + 2) % 3;
        const std::array<Mat3, 3> m = singular_element_integral(p, x.row(tri(edge.e, a)).transpose(), x.row(tri(edge.e, b)).transpose());
        flow[static_cast<std::size_t>(at)] = m[0] * edge.dn[static_cast<std::size_t>(at)];
        flow[static_cast<std::size_t>(a)] = m[1] * edge.dn[static_cast<std::size_t>(a)];
        flow[static_cast<std::size_t>(b)] = m[2] * edge.dn[static_cast<std::size_t>(b)];
      } else {
        const QuadraticTriangle T = flat_element(x, tri, edge.e);
        const Vec3 zero = Vec3::Zero();
        flow[0] = adaptive_element_apply(p, T, edge.dn[0], zero, zero);
        flow[1] = adaptive_element_apply(p, T, zero, edge.dn[1], zero);
        flow[2] = adaptive_element_apply(p, T, zero, zero, edge.dn[2]);
      }
      for (int k = 0; k < 3; ++k) {
        const Eigen::Index c = column[static_cast<std::size_t>(tri(edge.e, k))];
        if (c >= 0 && edge.dn[static_cast<std::size_t>(k)].squaredNorm() > 0)
          edge_at_nodes_.block<3, 1>(3 * i, c) += fmm::Stokeslet::scale() * flow[static_cast<std::size_t>(k)];
      }
    }
  }
}

void FixedWall::add_edge_pressure(const Points& t, const Points& targets, Points& u) const {
  if (edge_elements_.empty()) return;
  const Triangles& tri = mesh_.triangles;
  const Points& x = mesh_.vertices;
#pragma omp parallel for schedule(dynamic, 16) num_threads(layer_threads(opt_.layer))
  for (Eigen::Index i = 0; i < targets.rows(); ++i) {
    const Vec3 p = targets.row(i).transpose();
    Vec3 sum = Vec3::Zero();
    for (const EdgeElement& edge : edge_elements_) {
      std::array<Vec3, 3> c;
      for (int k = 0; k < 3; ++k) {
        const Eigen::Index node = tri(edge.e, k);
        c[static_cast<std::size_t>(k)] = edge.dn[static_cast<std::size_t>(k)] * normal_.row(node).dot(t.row(node));
      }
      sum += adaptive_element_apply(p, flat_element(x, tri, edge.e), c[0], c[1], c[2]);
    }
    u.row(i) += fmm::Stokeslet::scale() * sum.transpose();
  }
}

void FixedWall::build_preconditioner() {
  near_ = near_field_matrix(mesh_.vertices, mesh_.triangles, S_->near_field_lists(), 0, nullptr, layer_threads(opt_.layer));
  near_.makeCompressed();
  near_lu_.analyzePattern(near_);
  near_lu_.factorize(near_);
  preconditioned_ = near_lu_.info() == Eigen::Success;  // a singular near field: plain GMRES
}

FixedWall::~FixedWall() = default;

double FixedWall::preconditioner_megabytes() const {
  if (!preconditioned_) return 0;
  const double nonzeros = static_cast<double>(near_.nonZeros() + near_lu_.nnzL() + near_lu_.nnzU());
  return nonzeros * (sizeof(double) + sizeof(int)) / 1e6;
}

void FixedWall::apply(const Points& f, Points& Sf) {
  if (op_)
    op_->apply(f, Sf);
  else
    S_->apply(mesh_.vertices, f, Sf);
  if (!edge_nodes_.empty()) {  // the edge nodes' pressures through the integrated columns (§3.5)
    Eigen::VectorXd p(static_cast<Eigen::Index>(edge_nodes_.size()));
    for (std::size_t c = 0; c < edge_nodes_.size(); ++c)
      p[static_cast<Eigen::Index>(c)] = normal_.row(edge_nodes_[c]).dot(f.row(edge_nodes_[c]));
    flat(Sf) += edge_at_nodes_ * p;
  }
}

FixedWallSolve FixedWall::solve(const Points* induced, double velocity_scale) {
  const auto start = std::chrono::steady_clock::now();
  Points b = rhs0_;
  if (induced) b += *induced;
  const Eigen::Index n = mesh_.num_nodes();
  Points f(n, 3), Sf(n, 3);
  Eigen::VectorXd pv;
  auto apply = [&](const Eigen::VectorXd& v, Eigen::VectorXd& y, Eigen::VectorXd*, double) {
    if (preconditioned_) {
      pv = near_lu_.solve(v);
      flat(f) = pv;
    } else {
      flat(f) = v;
    }
    this->apply(f, Sf);  // the member, not this lambda
    double nf = 0;
    for (Eigen::Index i = 0; i < n; ++i) nf += area_[i] * normal_.row(i).dot(f.row(i));
    for (Eigen::Index i = 0; i < n; ++i) Sf.row(i) += (nf / total_area_) * normal_.row(i);
    y = flat(Sf);
    return 0.0;
  };
  const Eigen::VectorXd bv = flat(b);
  const double rhs_norm = std::sqrt((weight_.array() * bv.array().square()).sum());
  const double scale = velocity_scale > 0 ? velocity_scale * std::sqrt(total_area_) : rhs_norm;
  FixedWallSolve out;
  if (rhs_norm <= opt_.gmres.tolerance * scale) {  // nothing to solve for at this tolerance
    traction_.setZero();
    out.converged = true;
    return out;
  }
  Eigen::VectorXd x = flat(traction_);
  if (preconditioned_) x = near_ * x;  // the warm start in the preconditioned unknown y = M f
  const GmresResult r = gmres(apply, bv, x, weight_, scale, opt_.gmres);
  // A warm start that already meets the tolerance is kept as it is: the round trip through the
  // preconditioner would move it by round-off, and a state solved again (an output at the state, a
  // restart) would then continue differently from one solved once.
  if (r.iterations > 0) flat(traction_) = preconditioned_ ? Eigen::VectorXd(near_lu_.solve(x)) : x;
  out.iterations = r.iterations;
  out.residual = r.residual / scale;
  out.converged = r.converged;
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

void FixedWall::set_traction(const Points& f) {
  if (f.rows() != traction_.rows() || f.cols() != 3)
    throw std::invalid_argument(fmt::format("FixedWall::set_traction: {}×{} for a wall of {} nodes", f.rows(), f.cols(),
                                            traction_.rows()));
  traction_ = f;
}

void FixedWall::single_layer_at(const Points& traction, const Points& targets, Points& u, OffSurfaceReport* report) {
  evaluate_off_surface(*S_, mesh_.vertices, traction, targets, u, report);
  add_edge_pressure(traction, targets, u);
}

void FixedWall::velocity_at(const Points& targets, Points& u, OffSurfaceReport* report) {
  single_layer_at(traction_, targets, u, report);
  if (moving_.empty()) return;
  const Triangles& t = mesh_.triangles;
  const Points& x = mesh_.vertices;
#pragma omp parallel for schedule(dynamic, 8) num_threads(layer_threads(opt_.layer))
  for (Eigen::Index k = 0; k < targets.rows(); ++k) {
    const Vec3 p = targets.row(k).transpose();
    Vec3 d = Vec3::Zero();
    for (const Eigen::Index e : moving_) {
      d += adaptive_element_double_layer(p, flat_element(x, t, e), velocity_.row(t(e, 0)).transpose(), velocity_.row(t(e, 1)).transpose(),
                                         velocity_.row(t(e, 2)).transpose());
    }
    u.row(k) += fmm::Stokeslet::scale() * d.transpose();
  }
}

}  // namespace capsflow
