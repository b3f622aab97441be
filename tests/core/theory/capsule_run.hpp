#pragma once
// A short capsule run for the comparisons with the small-deformation theory: a plain-membrane
// sphere from rest, Heun at half the automatic stable step (adjusted to land on the sample
// times), and the flow-plane observables (geometry/flow_plane) at the sample times.
#include <string>
#include <vector>

#include "capsflow/core/rhs/capsule_dynamics.hpp"
#include "capsflow/core/stepping/heun.hpp"
#include "capsflow/core/stepping/stability.hpp"
#include "capsflow/core/geometry/flow_plane.hpp"
#include "capsflow/core/mesh/reference_mesh.hpp"
#include "capsflow/core/mesh/stats.hpp"
#include "capsflow/core/scene/scene.hpp"

namespace capsflow::test {

struct CapsuleSample {
  double t = 0;
  InPlaneShape shape;
  double tank_treading = 0;  // rate since the previous sample (NaN at the first)
};

struct CapsuleRun {
  Scene scene;
  std::vector<CapsuleSample> samples;
};

// `overrides` are scene assignments ("flow.ca_s=0.01", ...) on top of a membrane sphere with
// the direct far field; `times` ascending and > 0.
inline CapsuleRun run_capsule(const std::vector<std::string>& overrides, const std::vector<double>& times) {
  std::vector<std::string> all = {"mesh.shape=\"sphere\"", "wall.model=\"membrane\"", "fluid.backend=\"direct\""};
  all.insert(all.end(), overrides.begin(), overrides.end());
  CapsuleRun run{parse_scene(default_scene_toml(), "small-deformation", all), {}};
  const SurfaceMesh ref = make_reference_mesh(run.scene.mesh);
  CapsuleDynamics dyn(run.scene, ref);
  Heun heun;
  const FlowPlane plane = flow_plane(dyn.gradient());
  TankTreadingMeter meter(plane);
  Points x = ref.vertices;
  // Half the stable step: Heun's error on the relaxation (rates ≤ 2.3/Ca) stays ≪ the mesh error.
  const double dt_max = 0.5 * stability_estimate(run.scene, min_edge_length(ref)).limit();
  meter.update(SurfaceMesh{x, ref.triangles}, 0.0);
  double t = 0;
  for (const double t_out : times) {
    const int n = static_cast<int>(std::ceil((t_out - t) / dt_max - 1e-9));
    const double dt = (t_out - t) / n;
    for (int k = 0; k < n; ++k) heun.step(dyn, x, dt);
    t = t_out;
    const SurfaceMesh mesh{x, ref.triangles};
    run.samples.push_back({t, in_plane_shape(mesh, plane), meter.update(mesh, t)});
  }
  return run;
}

}  // namespace capsflow::test
