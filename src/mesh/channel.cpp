#include "capsflow/core/mesh/channel.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace capsflow {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The cross-section ring in the (y, z) plane, counter-clockwise seen from +x (angle from y to z).
std::vector<Eigen::Vector2d> cross_section_ring(const ChannelGeometry& g, int& per_side) {
  std::vector<Eigen::Vector2d> ring;
  if (g.shape == ChannelShape::Tube) {
    const int n = std::max(6, static_cast<int>(std::lround(2 * kPi * g.radius / g.element_size)));
    for (int k = 0; k < n; ++k) ring.emplace_back(g.radius * std::cos(2 * kPi * k / n), g.radius * std::sin(2 * kPi * k / n));
    per_side = 0;
    return ring;
  }
  const int n = std::max(2, static_cast<int>(std::lround(2 * g.radius / g.element_size)));
  const double W = g.radius, s = 2 * W / n;
  for (int k = 0; k < n; ++k) ring.emplace_back(W, -W + k * s);   // y = W, upwards
  for (int k = 0; k < n; ++k) ring.emplace_back(W - k * s, W);    // z = W, leftwards
  for (int k = 0; k < n; ++k) ring.emplace_back(-W, W - k * s);   // y = −W, downwards
  for (int k = 0; k < n; ++k) ring.emplace_back(-W + k * s, -W);  // z = −W, rightwards
  per_side = n;
  return ring;
}

// Appends triangle (a, b, c) oriented so that its normal points along `outward` (the caps are
// planar, so one sign test per triangle orients it).
void add_oriented(std::vector<Eigen::Vector3i>& tri, const Points& x, int a, int b, int c, const Vec3& outward) {
  const Vec3 n = (x.row(b) - x.row(a)).transpose().cross((x.row(c) - x.row(a)).transpose());
  if (n.dot(outward) >= 0)
    tri.emplace_back(a, b, c);
  else
    tri.emplace_back(a, c, b);
}

// A tube's cap: concentric rings of R·i/m with about n·i/m nodes (one node at the centre), each
// pair of neighbouring rings zipped by angle; the outermost ring is the side's end ring `rim`.
void tube_cap(std::vector<Vec3>& nodes, std::vector<Eigen::Vector3i>& tri_out, const std::vector<int>& rim,
              double x_cap, double R, const Vec3& outward) {
  const int n = static_cast<int>(rim.size());
  const int m = std::max(1, static_cast<int>(std::lround(n / (2 * kPi))));
  std::vector<std::vector<int>> rings(static_cast<std::size_t>(m) + 1);
  for (int i = 0; i < m; ++i) {
    const int count = i == 0 ? 1 : std::max(3, static_cast<int>(std::lround(static_cast<double>(n) * i / m)));
    const double r = R * i / m;
    for (int k = 0; k < count; ++k) {
      rings[static_cast<std::size_t>(i)].push_back(static_cast<int>(nodes.size()));
      nodes.emplace_back(x_cap, r * std::cos(2 * kPi * k / count), r * std::sin(2 * kPi * k / count));
    }
  }
  rings[static_cast<std::size_t>(m)] = rim;
  Points x(static_cast<Eigen::Index>(nodes.size()), 3);
  for (std::size_t i = 0; i < nodes.size(); ++i) x.row(static_cast<Eigen::Index>(i)) = nodes[i].transpose();
  for (int i = 0; i < m; ++i) {
    const auto& A = rings[static_cast<std::size_t>(i)];
    const auto& B = rings[static_cast<std::size_t>(i) + 1];
    const int a = static_cast<int>(A.size()), b = static_cast<int>(B.size());
    int ia = 0, ib = 0;
    while (ib < b || (a > 1 && ia < a)) {
      const double next_a = (ia + 1.0) / a, next_b = (ib + 1.0) / b;  // fractions of a turn
      if (ib < b && (a == 1 || ia >= a || next_b <= next_a)) {
        add_oriented(tri_out, x, A[static_cast<std::size_t>(ia % a)], B[static_cast<std::size_t>(ib)],
                     B[static_cast<std::size_t>((ib + 1) % b)], outward);
        ++ib;
      } else {
        add_oriented(tri_out, x, A[static_cast<std::size_t>(ia)], B[static_cast<std::size_t>(ib % b)],
                     A[static_cast<std::size_t>((ia + 1) % a)], outward);
        ++ia;
      }
    }
  }
}

// A square duct's cap: the (per_side + 1)² grid of the cross-section, its boundary the end ring
// `rim` (in cross_section_ring's order), each cell split along alternating diagonals.
void duct_cap(std::vector<Vec3>& nodes, std::vector<Eigen::Vector3i>& tri_out, const std::vector<int>& rim,
              double x_cap, double W, int n, const Vec3& outward) {
  auto rim_index = [n](int i, int k) {  // position of grid point (i, k) on the ring, or −1
    if (i == n) return k == n ? n : (k == 0 ? 0 : k);
    if (k == n) return n + (n - i);
    if (i == 0) return 2 * n + (n - k);
    if (k == 0) return 3 * n + i;
    return -1;
  };
  std::vector<int> id(static_cast<std::size_t>((n + 1) * (n + 1)));
  for (int i = 0; i <= n; ++i)
    for (int k = 0; k <= n; ++k) {
      const int r = rim_index(i, k);
      int& slot = id[static_cast<std::size_t>(i * (n + 1) + k)];
      if (r >= 0) {
        slot = rim[static_cast<std::size_t>(r % (4 * n))];
      } else {
        slot = static_cast<int>(nodes.size());
        nodes.emplace_back(x_cap, -W + 2 * W * i / n, -W + 2 * W * k / n);
      }
    }
  Points x(static_cast<Eigen::Index>(nodes.size()), 3);
  for (std::size_t i = 0; i < nodes.size(); ++i) x.row(static_cast<Eigen::Index>(i)) = nodes[i].transpose();
  auto at = [&](int i, int k) { return id[static_cast<std::size_t>(i * (n + 1) + k)]; };
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < n; ++k) {
      if ((i + k) % 2 == 0) {
        add_oriented(tri_out, x, at(i, k), at(i + 1, k), at(i + 1, k + 1), outward);
        add_oriented(tri_out, x, at(i, k), at(i + 1, k + 1), at(i, k + 1), outward);
      } else {
        add_oriented(tri_out, x, at(i, k), at(i + 1, k), at(i, k + 1), outward);
        add_oriented(tri_out, x, at(i + 1, k), at(i + 1, k + 1), at(i, k + 1), outward);
      }
    }
}

// The side's stations along x, about `spacing` apart: uniform from inlet to outlet, or in a
// constriction uniform on each piece (wide, taper, narrow, taper, wide), a taper cut by its
// slant length so that its elements stay about `spacing` wide as the wall runs inward.
std::vector<double> station_positions(const ChannelGeometry& g, double spacing) {
  std::vector<double> breaks{-0.5 * g.length, 0.5 * g.length};
  if (!g.straight()) {
    const double c = g.constriction_center, half = 0.5 * g.constriction_length, T = g.constriction_taper;
    breaks = {-0.5 * g.length, c - half - T, c - half, c + half, c + half + T, 0.5 * g.length};
  }
  const double drop = g.straight() ? 0.0 : g.radius - std::min(g.constriction_height, g.constriction_width);
  std::vector<double> xs{breaks.front()};
  for (std::size_t k = 0; k + 1 < breaks.size(); ++k) {
    const double a = breaks[k], b = breaks[k + 1];
    if (b <= a) continue;  // a constriction of zero length
    const bool taper = !g.straight() && (k == 1 || k == 3);
    const double run = taper ? std::hypot(b - a, drop) : b - a;
    const int pieces = std::max(1, static_cast<int>(std::lround(run / spacing)));
    for (int j = 1; j <= pieces; ++j) xs.push_back(j == pieces ? b : a + (b - a) * j / pieces);
  }
  return xs;
}

}  // namespace

double channel_cross_section_area(const ChannelGeometry& g) {
  return g.shape == ChannelShape::Tube ? kPi * g.radius * g.radius : 4 * g.radius * g.radius;
}

double distance_from_axis(const ChannelGeometry& g, double y, double z) {
  return g.shape == ChannelShape::Tube ? std::hypot(y, z) : std::max(std::abs(y), std::abs(z));
}

Eigen::Vector2d channel_half_sizes(const ChannelGeometry& g, double x) {
  const Eigen::Vector2d wide(g.radius, g.radius);
  if (g.straight()) return wide;
  const Eigen::Vector2d narrow(g.constriction_height, g.constriction_width);
  const double from_middle = std::abs(x - g.constriction_center) - 0.5 * g.constriction_length;
  if (from_middle <= 0) return narrow;
  if (from_middle >= g.constriction_taper) return wide;
  return narrow + (wide - narrow) * (from_middle / g.constriction_taper);
}

double relative_distance_from_axis(const ChannelGeometry& g, const Vec3& p) {
  if (g.shape == ChannelShape::Tube) return std::hypot(p.y(), p.z()) / g.radius;
  const Eigen::Vector2d h = channel_half_sizes(g, p.x());
  return std::max(std::abs(p.y()) / h.x(), std::abs(p.z()) / h.y());
}

ChannelMesh make_channel_mesh(const ChannelGeometry& g) {
  auto refuse = [](const std::string& what) { throw std::invalid_argument("channel: " + what); };
  if (!(g.radius > 0)) refuse("radius must be positive");
  if (!(g.length > 0)) refuse("length must be positive");
  if (!(g.element_size > 0)) refuse("element size must be positive");
  if (g.element_size > g.radius) refuse("element size above the radius (fewer than 6 elements around)");
  if (!g.straight()) {
    if (!(g.constriction_height > 0 && g.constriction_height <= g.radius)) refuse("constriction height not in (0, radius]");
    if (!(g.constriction_width > 0 && g.constriction_width <= g.radius)) refuse("constriction width not in (0, radius]");
    if (!(g.constriction_length >= 0)) refuse("constriction length must not be negative");
    if (!(g.constriction_taper > 0)) refuse("constriction taper must be positive");
    const double reach = 0.5 * g.constriction_length + g.constriction_taper;
    if (std::abs(g.constriction_center) + reach >= 0.5 * g.length) refuse("the constriction and its tapers reach a cap");
  }

  int per_side = 0;
  const std::vector<Eigen::Vector2d> ring = cross_section_ring(g, per_side);
  const int n = static_cast<int>(ring.size());
  double perimeter = 0;
  for (int k = 0; k < n; ++k) perimeter += (ring[static_cast<std::size_t>((k + 1) % n)] - ring[static_cast<std::size_t>(k)]).norm();
  const std::vector<double> xs = station_positions(g, perimeter / n);
  const int stations = static_cast<int>(xs.size()) - 1;

  std::vector<Vec3> nodes;
  std::vector<Eigen::Vector3i> tri;
  for (const double xj : xs) {
    const Eigen::Vector2d scale = channel_half_sizes(g, xj) / g.radius;
    for (const auto& p : ring) nodes.emplace_back(xj, scale.x() * p.x(), scale.y() * p.y());
  }
  auto side = [n](int j, int k) { return j * n + (k % n); };
  auto distance = [&nodes](int a, int b) { return (nodes[static_cast<std::size_t>(a)] - nodes[static_cast<std::size_t>(b)]).norm(); };
  // (j, k) → (j, k+1) runs along the ring (e_θ), (j, k) → (j+1, k) along x: e_θ × e_x points out.
  // Each quad is split along its diagonal (j, k+1)–(j+1, k), unless the other is shorter: a taper's
  // quads are sheared (the ring shrinks from one station to the next), and the long diagonal would
  // make slivers.
  for (int j = 0; j < stations; ++j)
    for (int k = 0; k < n; ++k) {
      const int a = side(j, k), b = side(j, k + 1), c = side(j + 1, k), d = side(j + 1, k + 1);
      if (distance(a, d) < (1 - 1e-9) * distance(b, c)) {
        tri.emplace_back(a, b, d);
        tri.emplace_back(a, d, c);
      } else {
        tri.emplace_back(a, b, c);
        tri.emplace_back(b, d, c);
      }
    }
  const std::size_t side_nodes = nodes.size();

  std::vector<int> inlet_rim(static_cast<std::size_t>(n)), outlet_rim(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) inlet_rim[static_cast<std::size_t>(k)] = side(0, k), outlet_rim[static_cast<std::size_t>(k)] = side(stations, k);
  std::vector<ChannelRegion> region(side_nodes, ChannelRegion::Side);
  auto cap = [&](const std::vector<int>& rim, double x_cap, const Vec3& outward, ChannelRegion r) {
    if (g.shape == ChannelShape::Tube)
      tube_cap(nodes, tri, rim, x_cap, g.radius, outward);
    else
      duct_cap(nodes, tri, rim, x_cap, g.radius, per_side, outward);
    region.resize(nodes.size(), r);
  };
  cap(inlet_rim, -0.5 * g.length, Vec3(-1, 0, 0), ChannelRegion::Inlet);
  cap(outlet_rim, 0.5 * g.length, Vec3(1, 0, 0), ChannelRegion::Outlet);

  ChannelMesh out;
  out.geometry = g;
  out.node_region = std::move(region);
  out.mesh.vertices.resize(static_cast<Eigen::Index>(nodes.size()), 3);
  for (std::size_t i = 0; i < nodes.size(); ++i) out.mesh.vertices.row(static_cast<Eigen::Index>(i)) = nodes[i].transpose();
  out.mesh.triangles.resize(static_cast<Eigen::Index>(tri.size()), 3);
  for (std::size_t e = 0; e < tri.size(); ++e) out.mesh.triangles.row(static_cast<Eigen::Index>(e)) = tri[e].transpose();
  return out;
}

}  // namespace capsflow
