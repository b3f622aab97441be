#include "capsflow/core/bie/off_surface.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "capsflow/core/bie/point_triangle.hpp"
#include "capsflow/fmm/stokeslet.hpp"

namespace capsflow {

namespace {

constexpr double kInv8Pi = fmm::Stokeslet::scale();

struct Element {
  QuadraticTriangle T;  // written about vertex 0
  Vec3 q[3];
};

// ∫ over the sub-triangle with parent barycentrics `bary` (rows; parameter-plane area
// param_area) of G(p − y) q(y) dS_y, refined until the sub-triangle is farther than 4 of its
// diameters from p (or max depth). Distances use the sub-triangle's corners on the surface.
Vec3 adaptive_integral(const Element& el, const Vec3& p, const Eigen::Matrix3d& bary, double param_area, int depth) {
  Vec3 y[3];
  for (int v = 0; v < 3; ++v) y[v] = el.T.position(bary(v, 1), bary(v, 2));
  const double diam = std::max({(y[1] - y[0]).norm(), (y[2] - y[1]).norm(), (y[0] - y[2]).norm()});
  const double dist = point_triangle_distance(p, y[0], y[1], y[2]);
  if (dist > 4 * diam || depth >= 14) {
    Vec3 sum = Vec3::Zero();
    if (dist <= 0) return sum;  // target on the element: no finite quadrature (reported as too close)
    for (const auto& r : kDunavant7) {
      const Eigen::RowVector3d lam = r[0] * bary.row(0) + r[1] * bary.row(1) + r[2] * bary.row(2);
      const Vec3 qq = lam[0] * el.q[0] + lam[1] * el.q[1] + lam[2] * el.q[2];
      sum += (r[3] * param_area * el.T.jacobian(lam[1], lam[2])) * stokeslet_apply(p - el.T.position(lam[1], lam[2]), qq);
    }
    return sum;
  }
  const std::array<Eigen::Matrix3d, 4> c = split_in_four(bary);
  Vec3 sum = Vec3::Zero();
  for (const auto& sub : c) sum += adaptive_integral(el, p, sub, param_area / 4, depth + 1);
  return sum;
}

}  // namespace

void evaluate_off_surface(SingleLayer& S, const Points& x, const Points& q, const Points& targets, Points& u,
                          OffSurfaceReport* report) {
  S.build_sources(x, q);  // also the current surface (vertex normals, edge midpoints)
  const Eigen::Index nt = targets.rows(), m = S.tri_.rows();
  u.resize(nt, 3);
  S.far_.set_targets(targets.data(), nt);
  S.far_field(u.data(), false);  // targets may coincide with edge midpoints

  // Uniform hash grid of element bounding boxes, cell = 2 × longest edge, so that every element
  // within 2 of its own sizes of a target overlaps one of the 27 cells around the target.
  double hmax = 0;
  for (Eigen::Index e = 0; e < m; ++e)
    for (int k = 0; k < 3; ++k) hmax = std::max(hmax, (x.row(S.tri_(e, k)) - x.row(S.tri_(e, (k + 1) % 3))).norm());
  const double cell = OffSurfaceReport::near_ratio * hmax;
  auto cell_of = [cell](double v) { return static_cast<long long>(std::floor(v / cell)); };
  auto key = [](long long i, long long j, long long k) { return (i * 73856093) ^ (j * 19349663) ^ (k * 83492791); };
  std::unordered_map<long long, std::vector<int>> grid;
  for (Eigen::Index e = 0; e < m; ++e) {
    Eigen::RowVector3d lo = x.row(S.tri_(e, 0)), hi = lo;
    for (int k = 1; k < 3; ++k) lo = lo.cwiseMin(x.row(S.tri_(e, k))), hi = hi.cwiseMax(x.row(S.tri_(e, k)));
    for (long long i = cell_of(lo[0]); i <= cell_of(hi[0]); ++i)
      for (long long j = cell_of(lo[1]); j <= cell_of(hi[1]); ++j)
        for (long long k = cell_of(lo[2]); k <= cell_of(hi[2]); ++k) grid[key(i, j, k)].push_back(static_cast<int>(e));
  }
  std::vector<double> ratio(static_cast<size_t>(nt), std::numeric_limits<double>::infinity());
  long refined = 0, too_close = 0;
#pragma omp parallel for schedule(dynamic, 16) reduction(+ : refined, too_close)
  for (Eigen::Index t = 0; t < nt; ++t) {
    const Vec3 p = targets.row(t).transpose();
    const long long ci = cell_of(p[0]), cj = cell_of(p[1]), ck = cell_of(p[2]);
    std::vector<int> seen;
    Vec3 corr = Vec3::Zero();
    bool any = false;
    for (long long i = ci - 1; i <= ci + 1; ++i)
      for (long long j = cj - 1; j <= cj + 1; ++j)
        for (long long k = ck - 1; k <= ck + 1; ++k) {
          auto it = grid.find(key(i, j, k));
          if (it == grid.end()) continue;
          for (int e : it->second) {
            if (std::find(seen.begin(), seen.end(), e) != seen.end()) continue;
            seen.push_back(e);
            Element el{S.surface_.element(x, e, 0), {}};
            Vec3 corner[3];
            double h = 0;
            for (int v = 0; v < 3; ++v) {
              corner[v] = x.row(S.tri_(e, v)).transpose();
              el.q[v] = q.row(S.tri_(e, v)).transpose();
            }
            for (int v = 0; v < 3; ++v) h = std::max(h, (corner[v] - corner[(v + 1) % 3]).norm());
            const double d = point_triangle_distance(p, corner[0], corner[1], corner[2]);
            ratio[static_cast<size_t>(t)] = std::min(ratio[static_cast<size_t>(t)], d / h);
            if (d >= OffSurfaceReport::near_ratio * h) continue;
            any = true;
            corr += adaptive_integral(el, p, Eigen::Matrix3d::Identity(), 0.5, 0);
            // The element's far-field terms, as the far field summed them (its block holds them negated).
            const StokesletBlock& fb = S.far_block_[static_cast<size_t>(e)];
            for (int k = SingleLayer::kFarLane; k < SingleLayer::kFarLane + 3; ++k) {
              const Vec3 r = p - Vec3(fb.y[0][k], fb.y[1][k], fb.y[2][k]);
              if (r.squaredNorm() > 0)  // the far-field sum skipped coincident pairs too
                corr += stokeslet_apply(r, Vec3(fb.f[0][k], fb.f[1][k], fb.f[2][k]));
            }
          }
        }
    if (any) {
      u.row(t) += kInv8Pi * corr.transpose();
      ++refined;
    }
    if (ratio[static_cast<size_t>(t)] < OffSurfaceReport::min_ratio) ++too_close;
  }
  if (report) {
    report->distance_ratio = std::move(ratio);
    report->refined = refined;
    report->too_close = too_close;
  }
}

}  // namespace capsflow
