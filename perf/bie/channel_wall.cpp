// The fixed wall's solve on closed channels at several element sizes (docs/channel.md §3.3, §3.5):
//   channel_wall [--sizes 0.3,0.2,0.15,0.1] [--constriction-sizes 0.2,0.14] [--plain-traction]
// prints, per shape and size, the wall's nodes, GMRES iterations, solve seconds and the error of
// each case of tests/core/bie/channel_cases.hpp, with the observed order between sizes; then the
// free rigid sphere on a tube's axis at a/R = 0.3 … 0.8, sphere levels 2 and 3, wall elements R/8
// and R/12, against Bungay & Brenner's uniformly valid fit (docs/channel.md §3.4); and the empty
// constricted duct's flux and narrow profile (§3.5). --plain-traction: without the edges' pressure
// along each element's normal (FixedWallOptions::edge_pressure), to compare.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <vector>

#include "channel_cases.hpp"

using namespace capsflow;

int main(int argc, char** argv) {
  CLI::App app{"fixed wall on closed channels: convergence against exact solutions"};
  std::vector<double> sizes{0.3, 0.2, 0.15, 0.1}, ratios{0.3, 0.5, 0.7, 0.8};
  app.add_option("--sizes", sizes, "element sizes (channel radius 1)")->delimiter(',');
  app.add_option("--ratios", ratios, "sphere-to-tube radius ratios of the free sphere")->delimiter(',');
  std::vector<double> constriction_sizes{0.2, 0.14};
  app.add_option("--constriction-sizes", constriction_sizes, "element sizes of the constricted duct")->delimiter(',');
  bool plain = false;
  app.add_flag("--plain-traction", plain, "the plain P1 traction (no edge pressure along the elements' normals)");
  CLI11_PARSE(app, argc, argv);
  channel_cases::wall_options.edge_pressure = !plain;
  std::printf("empty constricted duct (W = 1 narrowed to 0.5 × 0.5 over 3, tapers 0.5, length 9, V = 1, Q = 4)\n"
              "| h | wall nodes | GMRES iterations | solve s | flux wide | flux narrow | narrow profile error / centreline |\n"
              "|---:|---:|---:|---:|---:|---:|---:|\n");
  for (const double h : constriction_sizes) {
    const channel_cases::ConstrictionFlow f = channel_cases::empty_constriction(h);
    std::printf("| %.2f | %ld | %d | %.1f | %.5f | %.5f | %.2e |\n", h, f.nodes, f.iterations, f.seconds, f.flux_wide,
                f.flux_narrow, f.profile_error);
    std::fflush(stdout);
  }
  struct Case {
    const char* name;
    channel_cases::CaseResult (*run)(ChannelShape, double);
  };
  const Case cases[] = {{"outside point force: velocity inside / max |u| on the wall", channel_cases::outside_point_force},
                        {"inside point force: pressure drop, relative error", channel_cases::inside_point_force},
                        {"full traction, empty channel: velocity inside / V", channel_cases::full_traction_empty_channel}};
  for (const Case& c : cases) {
    std::printf("\n%s\n| shape | h | wall nodes | GMRES iterations | solve s | error | order |\n|---|---:|---:|---:|---:|---:|---:|\n",
                c.name);
    for (const ChannelShape shape : {ChannelShape::Tube, ChannelShape::SquareDuct}) {
      double previous = 0, previous_h = 0;
      for (const double h : sizes) {
        const channel_cases::CaseResult r = c.run(shape, h);
        std::printf("| %s | %.2f | %ld | %d%s | %.1f | %.2e |", to_string(shape), h, r.nodes, r.iterations,
                    r.converged ? "" : " (not converged)", r.seconds, r.error);
        if (previous > 0)
          std::printf(" %.2f |\n", std::log(previous / r.error) / std::log(previous_h / h));
        else
          std::printf(" |\n");
        std::fflush(stdout);
        previous = r.error, previous_h = h;
      }
    }
  }
  // U/V of Bungay & Brenner's fit, K_s/K_t (tests/core/bie/test_fixed_wall.cpp, bungay_brenner_velocity).
  std::printf("\nfree rigid sphere on a tube's axis: U/V against Bungay & Brenner's fit\n"
              "| a/R | sphere nodes | wall nodes | GMRES iterations | solve s | U/V | fit | difference | dp+ R/(mu V) caps | reciprocal |\n"
              "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  for (const double ratio : ratios)
    for (const int level : {2, 3})
      for (const double per_radius : {8.0, 12.0}) {
        const channel_cases::SphereResult r = channel_cases::free_sphere_on_axis(ratio, level, 1 / ratio / per_radius);
        const double fit = channel_cases::bungay_brenner_velocity(ratio);
        std::printf("| %.1f | %ld | %ld | %d%s | %.1f | %.5f | %.4f | %+.2f %% | %.4f | %.4f |\n", ratio, r.sphere_nodes,
                    r.wall_nodes, r.iterations, r.converged ? "" : " (not converged)", r.seconds, r.velocity_ratio, fit,
                    100 * (r.velocity_ratio / fit - 1), r.pressure_drop_caps, r.pressure_drop_reciprocal);
        std::fflush(stdout);
      }
}
