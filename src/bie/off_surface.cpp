#include "capsflow/core/bie/off_surface.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "capsflow/core/bie/point_triangle.hpp"
#include "capsflow/fmm/stokeslet.hpp"

namespace capsflow {

namespace {
constexpr double kInv8Pi = fmm::Stokeslet::scale();
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
            Vec3 corner[3];
            double h = 0;
            for (int v = 0; v < 3; ++v) corner[v] = x.row(S.tri_(e, v)).transpose();
            for (int v = 0; v < 3; ++v) h = std::max(h, (corner[v] - corner[(v + 1) % 3]).norm());
            const double d = point_triangle_distance(p, corner[0], corner[1], corner[2]);
            ratio[static_cast<size_t>(t)] = std::min(ratio[static_cast<size_t>(t)], d / h);
            if (d >= OffSurfaceReport::near_ratio * h) continue;
            any = true;
            corr += adaptive_element_apply(p, S.surface_.element(x, e, 0), q.row(S.tri_(e, 0)).transpose(),
                                           q.row(S.tri_(e, 1)).transpose(), q.row(S.tri_(e, 2)).transpose()) -
                    S.element_far_terms(e, p);
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
