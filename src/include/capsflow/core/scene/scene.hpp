#pragma once
// A scene: everything a run needs, read from TOML (keys: docs/scene-and-output.md §2) and fully resolved
// (defaults filled in, derived parameters computed). Validation is strict: unknown keys, wrong
// types and out-of-range values raise SceneError naming the file, line and key.
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "capsflow/core/bie/backend_choice.hpp"
#include "capsflow/core/dynamics/health_conditions.hpp"
#include "capsflow/core/dynamics/time_scheme.hpp"
#include "capsflow/core/mesh/generation.hpp"
#include "capsflow/core/scene/options.hpp"
#include "capsflow/core/types.hpp"
#include "capsflow/shell/laws.hpp"

namespace capsflow {

class SceneError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct MeshSpec {
  BaseSolid base = BaseSolid::Icosahedron;
  int level = 4;                     // subdivisions: 20·4^level or 8·4^level elements
  MeshShape shape = MeshShape::Spheroid;
  double aspect = 1.4;               // a/b of the spheroid
  int axis = 3;                      // symmetry axis of the spheroid (1, 2 or 3)
  std::string file;                  // user mesh (.off/.ply); overrides base/level/shape
};

struct WallSpec {
  WallModel model = WallModel::Gsmb;
  shell::LawKind law = shell::LawKind::GeneralizedHooke;  // gh | nh | skalak | mr (shell/laws.hpp)
  double thickness = 0.03;     // h/ℓ = α (GSMB)
  double poisson = 0.5;        // ν_s = ν
  double skalak_c = 1.0;       // Skalak area-dilation parameter C
  double mooney_rivlin_psi = 0.1;  // Mooney–Rivlin Ψ = C2/(C1 + C2) in [0, 1]; 0 is NH
  int max_newton = 100;        // GSMB: iteration cap of the rotation Newton solve (shell::GsmbOptions)
};

struct FlowSpec {
  FlowType type = FlowType::PlanarHyperbolic;
  double ca_s = 0.1;                       // μγ̇ℓ/G_s
  double ca_v = 0.003;                     // μγ̇/G = ca_s·α (GSMB only; NaN for a membrane without thickness)
  Mat3 gradient = Mat3::Zero();            // velocity gradient L (v∞ = L x), resolved for every type
  bool ca_s_from_ca_v = true;              // ca_s not given: derived from ca_v (given or default) and the thickness
};

struct TimeSpec {
  TimeScheme scheme = TimeScheme::Rkc;  // never Auto after parsing (resolved from the wall model)
  bool scheme_auto = true;              // the scheme was chosen by "auto" (for the log)
  double tolerance = 1e-6;       // RKC local error per step (RMS over nodes, units of ℓ; docs/time-integration.md §5.7)
  bool dt_auto = true;           // RKC: error-controlled step; Heun: the stability-limited step
  double dt = 0;                 // fixed step (when !dt_auto)
  double dt_safety = 0.7;        // fraction of the (calibrated) stability limit used by dt = "auto"
  double t_end = 5.0;
  bool stop_at_steady = false;
  double steady_tol = 5e-4;      // area change over γ̇t = 1, relative to 4πℓ² (paper §4.1)
  std::vector<HealthCondition> stop_on;  // stop the run when one of these conditions begins
};

struct FluidSpec {
  BackendRequest backend = BackendRequest::Auto;
  double tolerance = 1e-6;       // far-field relative accuracy (FMM order; direct: single-precision pairs from 1e-5)
  SurfaceGeometry geometry = SurfaceGeometry::Flat;  // surface seen by the boundary integral (bie/single_layer.hpp)
  bool volume_correction = true; // remove the mean normal velocity (discrete flux error) each stage
  int fmm_order = 0;             // > 0 forces the FMM order (4..14) instead of the tolerance's
  int verify_every = 0;          // > 0: every N evaluations also sum the far field directly and compare
};

struct OutputSpec {
  double every = 0.1;                       // output cadence in γ̇t
  std::vector<OutputField> fields;
  double checkpoint_every = 0.5;            // in γ̇t; 0 disables periodic checkpoints
};

struct Scene {
  std::string source = "<built-in default>";  // file the scene came from
  std::string toml_text;                      // verbatim input (for metadata)
  MeshSpec mesh;
  WallSpec wall;
  FlowSpec flow;
  TimeSpec time;
  FluidSpec fluid;
  OutputSpec output;
  bool wants_field(OutputField f) const;
};

// The built-in default scene: a quick, coarse version of the paper's case.
const std::string& default_scene_toml();

// Parse TOML text (name is used in messages), apply "key.path=value" overrides, validate, resolve.
Scene parse_scene(const std::string& toml_text, const std::string& name,
                  const std::vector<std::string>& overrides = {});
// Reads a scene file: a missing file, a folder, an unreadable file and an HDF5 or binary file
// each have their own message. A relative mesh.file in the file is resolved against the scene's
// folder (one given with --set against the working directory).
Scene load_scene(const std::string& path, const std::vector<std::string>& overrides = {});

// When Ca_s is derived from Ca_v (flow.ca_s not given), a one-line note that Ca_s = Ca_v/thickness
// moves with the thickness (printed by `capsflow info` and at the start of a run); else "".
std::string capillary_note(const Scene& scene);

nlohmann::json to_json(const Scene& scene);
// Canonical TOML of the resolved scene (every key explicit), for output and restarts.
std::string to_toml(const Scene& scene);

}  // namespace capsflow
