#include "capsflow/core/bie/fixed_single_layer.hpp"

#include <omp.h>

#include <algorithm>
#include <array>
#include <numeric>
#include <stdexcept>

#include "capsflow/core/bie/quadrature.hpp"
#include "capsflow/fmm/stokeslet.hpp"

namespace capsflow {

namespace {

constexpr double kInv8Pi = fmm::Stokeslet::scale();

// One node's row of 3×3 blocks, gathered by column node (slot_ marks where each node's block is).
class BlockRow {
 public:
  explicit BlockRow(Eigen::Index n) : slot_(static_cast<std::size_t>(n), -1) {}
  void add(int node, const Mat3& block) {
    int& s = slot_[static_cast<std::size_t>(node)];
    if (s < 0) {
      s = static_cast<int>(nodes_.size());
      nodes_.push_back(node);
      blocks_.push_back(block);
    } else {
      blocks_[static_cast<std::size_t>(s)] += block;
    }
  }
  // The blocks by increasing column node (scaled), and the row emptied for the next node.
  std::vector<std::pair<int, Mat3>> take(double scale) {
    std::vector<std::pair<int, Mat3>> out;
    out.reserve(nodes_.size());
    for (std::size_t k = 0; k < nodes_.size(); ++k) {
      out.emplace_back(nodes_[k], scale * blocks_[k]);
      slot_[static_cast<std::size_t>(nodes_[k])] = -1;
    }
    std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    nodes_.clear();
    blocks_.clear();
    return out;
  }

 private:
  std::vector<int> slot_, nodes_;
  std::vector<Mat3> blocks_;
};

// Element e's rule point (barycentrics l about its vertex 0, weight w of the reference triangle)
// seen from xi: the blocks w J l_k G(xi − y) for its vertices k, at the position y given, or at
// the rule point itself when y is null.
void add_rule_point(BlockRow& row, const Vec3& xi, const Triangles& t, Eigen::Index e, const QuadraticTriangle& T,
                    const double* l, double w, const double* y) {
  const Vec3 p = y ? Vec3(y[0], y[1], y[2]) : T.position(l[1], l[2]);
  const Mat3 G = (w * T.jacobian(l[1], l[2])) * stokeslet_matrix(xi - p);
  for (int k = 0; k < 3; ++k) row.add(t(e, k), l[k] * G);
}

}  // namespace

SparseRows near_field_matrix(const Points& x, const Triangles& t, const NearFieldLists& lists, int ring_depth,
                             const FarField<fmm::Stokeslet>* far, int threads) {
  const Eigen::Index n = x.rows();
  std::vector<std::vector<std::pair<int, Mat3>>> rows(static_cast<std::size_t>(n));
  // The far field's terms of element e negated: its rule points at the positions the far field
  // summed them (far_field.hpp: the two sides of an edge at the one source's).
  auto subtract_far = [&](BlockRow& row, const Vec3& xi, Eigen::Index e) {
    const QuadraticTriangle T = flat_element(x, t, e);
    for (int k = 0; k < 3; ++k)
      add_rule_point(row, xi, t, e, T, far->rule_point(k), -1.0 / 6.0, far->slot_position(static_cast<std::size_t>(3 * e + k)));
  };
#pragma omp parallel num_threads(threads)
  {
    BlockRow row(n);
#pragma omp for schedule(dynamic, 64)
    for (Eigen::Index i = 0; i < n; ++i) {
      const Vec3 xi = x.row(i).transpose();
      for (const int e : lists.touching(i)) {
        int first = 0;  // the element written about node i
        while (t(e, first) != i) ++first;
        const int v1 = t(e, (first + 1) % 3), v2 = t(e, (first + 2) % 3);
        const std::array<Mat3, 3> m = singular_element_integral(xi, x.row(v1).transpose(), x.row(v2).transpose());
        row.add(static_cast<int>(i), m[0]), row.add(v1, m[1]), row.add(v2, m[2]);
        if (far) subtract_far(row, xi, e);
      }
      for (const int e : lists.ring(i)) {
        const std::array<Mat3, 3> m = refined_element_integral(xi, flat_element(x, t, e), std::max(ring_depth, 0));
        for (int k = 0; k < 3; ++k) row.add(t(e, k), m[static_cast<std::size_t>(k)]);
        if (far) subtract_far(row, xi, e);
      }
      if (far)
        for (const int e : lists.band(i)) {
          const QuadraticTriangle T = flat_element(x, t, e);
          for (int g = 0; g < 3; ++g) add_rule_point(row, xi, t, e, T, kGaussBary[g], 1.0 / 6.0, nullptr);
          subtract_far(row, xi, e);
        }
      rows[static_cast<std::size_t>(i)] = row.take(kInv8Pi);
    }
  }
  // Compressed rows: node i's blocks give rows 3i..3i+2, 3 entries per block each.
  SparseRows m(3 * n, 3 * n);
  std::vector<Eigen::Index> blocks(static_cast<std::size_t>(n) + 1, 0);
  for (Eigen::Index i = 0; i < n; ++i)
    blocks[static_cast<std::size_t>(i) + 1] = blocks[static_cast<std::size_t>(i)] + static_cast<Eigen::Index>(rows[static_cast<std::size_t>(i)].size());
  m.resizeNonZeros(9 * blocks.back());
  int* outer = m.outerIndexPtr();
  int* inner = m.innerIndexPtr();
  double* value = m.valuePtr();
#pragma omp parallel for schedule(static) num_threads(threads)
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto& r = rows[static_cast<std::size_t>(i)];
    const Eigen::Index width = 3 * static_cast<Eigen::Index>(r.size());
    for (int a = 0; a < 3; ++a) {
      const Eigen::Index begin = 9 * blocks[static_cast<std::size_t>(i)] + a * width;
      outer[3 * i + a] = static_cast<int>(begin);
      for (std::size_t k = 0; k < r.size(); ++k)
        for (int b = 0; b < 3; ++b) {
          const Eigen::Index at = begin + 3 * static_cast<Eigen::Index>(k) + b;
          inner[at] = 3 * r[k].first + b;
          value[at] = r[k].second(a, b);
        }
    }
  }
  outer[3 * n] = static_cast<int>(9 * blocks.back());
  return m;
}

FixedSingleLayer::FixedSingleLayer(const SurfaceMesh& surface, const SingleLayerOptions& opt, double dense_megabytes)
    : n_nodes_(surface.num_nodes()),
      threads_(layer_threads(opt)),
      lists_(surface.triangles, n_nodes_, opt.near_ring_depth < 0 ? 0 : near_ring_layers(opt),
             corrected_layers(opt, opt.near_ring_depth < 0 ? 0 : near_ring_layers(opt), kAutoCorrectedLayers)),
      surface_(surface.triangles, opt.geometry),
      far_(lists_, surface.num_elements(), n_nodes_, opt, threads_) {
  if (opt.geometry != SurfaceGeometry::Flat) throw std::invalid_argument("fixed single layer: flat facets only");
  Stopwatch clock;
  const Points& x = surface.vertices;
  const Triangles& t = surface.triangles;
  mixed_precision_ = uses_mixed_precision(opt.tolerance);
  // The sources' positions (their values are formed from each load in apply()).
  far_.place(x, surface_, [](const QuadraticTriangle& T, Eigen::Index, const double* l, double, double* y, double* v) {
    const Vec3 p = T.position(l[1], l[2]);
    for (int d = 0; d < 3; ++d) y[d] = p[d], v[d] = 0;
  }, [](const QuadraticTriangle&, Eigen::Index) {});
  far_.set_targets(x.data(), n_nodes_);
  // Per source, the weights (1/6) J λ_k of its slots' elements' vertices (single_layer.cpp's rule_point).
  const Eigen::Index ns = far_.sources();
  start_.assign(1, 0);
  for (Eigen::Index s = 0; s < ns; ++s) {
    for (const int slot : far_.slots(s)) {
      if (slot < 0) continue;
      const Eigen::Index e = slot / 3;
      const double* l = far_.rule_point(slot % 3);
      const double wj = flat_element(x, t, e).jacobian(l[1], l[2]) / 6.0;
      for (int k = 0; k < 3; ++k)
        if (l[k] != 0) node_.push_back(t(e, k)), weight_.push_back(wj * l[k]);
    }
    start_.push_back(static_cast<int>(node_.size()));
  }
  density_.resize(3 * static_cast<std::size_t>(ns));
  near_ = near_field_matrix(x, t, lists_, opt.near_ring_depth, &far_, threads_);
  if (72.0 * static_cast<double>(n_nodes_) * static_cast<double>(n_nodes_) / 1e6 <= dense_megabytes) make_dense(x);
  setup_seconds_ = clock.seconds();
}

void FixedSingleLayer::make_dense(const Points& x) {
  dense_ = near_;
  const Eigen::Index ns = far_.sources();
  const double* y = far_.positions();
#pragma omp parallel for schedule(dynamic, 16) num_threads(threads_)
  for (Eigen::Index i = 0; i < n_nodes_; ++i) {
    const Vec3 xi = x.row(i).transpose();
    for (Eigen::Index s = 0; s < ns; ++s) {
      const Mat3 G = kInv8Pi * stokeslet_matrix(xi - Vec3(y[3 * s], y[3 * s + 1], y[3 * s + 2]));
      for (int k = start_[static_cast<std::size_t>(s)]; k < start_[static_cast<std::size_t>(s) + 1]; ++k)
        dense_.block<3, 3>(3 * i, 3 * node_[static_cast<std::size_t>(k)]) += weight_[static_cast<std::size_t>(k)] * G;
    }
  }
  near_ = SparseRows();  // in the dense matrix
}

FixedSingleLayer::~FixedSingleLayer() = default;

double FixedSingleLayer::megabytes() const {
  if (dense()) return static_cast<double>(dense_.size()) * sizeof(double) / 1e6;
  const double near = static_cast<double>(near_.nonZeros()) * (sizeof(double) + sizeof(int)) +
                      static_cast<double>(near_.outerSize() + 1) * sizeof(int);
  const double sources = static_cast<double>(weight_.size()) * (sizeof(double) + sizeof(int)) +
                         static_cast<double>(start_.size() + density_.size()) * sizeof(double);
  return (near + sources) / 1e6;
}

void FixedSingleLayer::apply(const Points& q, Points& u) {
  if (q.rows() != n_nodes_) throw std::invalid_argument("fixed single layer: the load must have one row per node");
  Stopwatch clock;
  u.resize(n_nodes_, 3);
  if (dense()) {  // rows split among the threads (Eigen's own mat-vec runs on one)
    const Eigen::Map<const Eigen::VectorXd> qv(q.data(), 3 * n_nodes_);
    Eigen::Map<Eigen::VectorXd> uv(u.data(), 3 * n_nodes_);
#pragma omp parallel num_threads(threads_)
    {
      const Eigen::Index rows = 3 * n_nodes_, parts = omp_get_num_threads(), k = omp_get_thread_num();
      const Eigen::Index begin = rows * k / parts, end = rows * (k + 1) / parts;
      uv.segment(begin, end - begin).noalias() = dense_.middleRows(begin, end - begin) * qv;
    }
    clock.lap(times_, Phase::BieNear);
    ++evaluations_;
    return;
  }
  const Eigen::Index ns = far_.sources();
#pragma omp parallel for schedule(static) num_threads(threads_)
  for (Eigen::Index s = 0; s < ns; ++s) {
    double f[3] = {0, 0, 0};
    for (int k = start_[static_cast<std::size_t>(s)]; k < start_[static_cast<std::size_t>(s) + 1]; ++k)
      for (int d = 0; d < 3; ++d) f[d] += weight_[static_cast<std::size_t>(k)] * q(node_[static_cast<std::size_t>(k)], d);
    for (int d = 0; d < 3; ++d) density_[3 * static_cast<std::size_t>(s) + static_cast<std::size_t>(d)] = f[d];
  }
  clock.lap(times_, Phase::BieSources);
  if (far_.backend() == FarFieldBackend::Fmm)
    far_.evaluate(FarField<fmm::Stokeslet>::kMainFmm, density_.data(), u.data());
  else
    far_.direct(density_.data(), u.data(), mixed_precision_ ? DirectPairs::Single : DirectPairs::Fast);
  clock.lap(times_, Phase::BieFar);
  if (far_.check_due(evaluations_)) {
    far_.record(far_.compare_with_direct(density_.data(), u.data(), evaluations_));
    clock.lap(times_, Phase::BieVerify);
  }
  const double* qv = q.data();
  double* uv = u.data();
  const int* outer = near_.outerIndexPtr();
  const int* inner = near_.innerIndexPtr();
  const double* value = near_.valuePtr();
#pragma omp parallel for schedule(static) num_threads(threads_)
  for (Eigen::Index r = 0; r < 3 * n_nodes_; ++r) {
    double sum = 0;
    for (int k = outer[r]; k < outer[r + 1]; ++k) sum += value[k] * qv[inner[k]];
    uv[r] += sum;
  }
  clock.lap(times_, Phase::BieNear);
  ++evaluations_;
}

}  // namespace capsflow
