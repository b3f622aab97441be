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
#include "capsflow/core/health/health_conditions.hpp"
#include "capsflow/core/stepping/time_scheme.hpp"
#include "capsflow/core/mesh/generation.hpp"
#include "capsflow/core/scene/options.hpp"
#include "capsflow/core/types.hpp"
#include "capsflow/shell/laws.hpp"

namespace capsflow {

class SceneError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The sections of a scene. Every key's default, accepted values and doc line are declared once, in
// the key table (src/scene/scene_keys.cpp); a default-constructed section holds the table's
// defaults, a default-constructed Scene also the derived values (Ca_s, the flow gradient).
struct MeshSpec {
  MeshSpec();
  BaseSolid base;
  int level;                         // subdivisions: 20·4^level or 8·4^level elements
  MeshShape shape;
  double aspect;                     // a/b of the spheroid
  int axis;                          // symmetry axis of the spheroid (1, 2 or 3)
  std::string file;                  // user mesh (.off/.ply); overrides base/level/shape
};

struct WallSpec {
  WallSpec();
  WallModel model;
  shell::LawKind law;          // gh | nh | skalak | mr (shell/laws.hpp)
  double thickness;            // h/ℓ = α (GSMB)
  double poisson;              // ν_s = ν
  double skalak_c;             // Skalak area-dilation parameter C
  double mooney_rivlin_psi;    // Mooney–Rivlin Ψ = C2/(C1 + C2) in [0, 1]; 0 is NH
  int max_newton;              // GSMB: iteration cap of the rotation Newton solve (shell::GsmbOptions)
  double prestress;            // pre-inflation α_p: the stress-free shape is the initial one shrunk by 1 + α_p
  double initial_stretch;      // the capsule starts stretched along x1 by this factor at constant volume
};

struct FlowSpec {
  FlowSpec();
  FlowType type;
  double ca_s;                             // μγ̇ℓ/G_s
  double ca_v;                             // μγ̇/G = ca_s·α
  Mat3 gradient;                           // velocity gradient L (v∞ = L x), resolved for every type
  bool ca_s_from_ca_v = true;              // ca_s not given: derived from ca_v (given or default) and the thickness
};

struct TimeSpec {
  TimeSpec();
  TimeScheme scheme;             // as written; "auto" is resolved with the mesh (stepping/time_plan.hpp)
  double tolerance;              // local error per step (RMS over nodes, units of ℓ; docs/time-integration.md §5.6);
                                 // under "auto" the plan chooses (stepping/time_plan.hpp)
  bool tolerance_auto = true;
  bool dt_auto = true;           // RKC: error-controlled step; Heun: the stability-limited step
  double dt = 0;                 // fixed step (when !dt_auto)
  double dt_safety;              // fraction of the (calibrated) stability limit used by dt = "auto"
  double t_end;
  bool stop_at_steady;
  double steady_tol;             // area change over γ̇t = 1, relative to 4πℓ² (paper §4.1)
  std::vector<HealthCondition> stop_on;  // stop the run when one of these conditions begins
};

struct FluidSpec {
  FluidSpec();
  double viscosity_ratio;        // λ = inner/outer viscosity; 1: the single layer alone (bie/viscosity_ratio.hpp)
  int max_gmres;                 // λ ≠ 1: iteration cap of the second-kind GMRES solve
  bool reuse_identity_term;      // λ ≠ 1: reuse D̃[1]'s quadrature error between refreshes (§4.7.5)
  BackendRequest backend;
  double tolerance;              // far-field relative accuracy (FMM order; direct: single-precision pairs from 1e-5);
                                 // under "auto" 1e-6, and the FMM's follows the time step (far_field_tolerance())
  bool tolerance_auto = true;
  SurfaceGeometry geometry;      // surface seen by the boundary integral (bie/single_layer.hpp)
  FarFieldRule far_rule;         // far-field sources: auto (by geometry), edge midpoints or 3 Gauss points per element
  bool volume_correction;        // remove the mean normal velocity (discrete flux error) each stage
  int fmm_order;                 // > 0 forces the FMM order (4..14) instead of the tolerance's
  int fmm_leaf_size;             // > 0 forces the FMM's points per leaf instead of the calibrated one
  int verify_every;              // > 0: every N evaluations also sum the far field directly and compare
};

struct OutputSpec {
  OutputSpec();
  double every;                             // output cadence in γ̇t
  std::vector<OutputField> fields;
  double checkpoint_every;                  // in γ̇t; 0 disables periodic checkpoints
};

// Several capsules in a row, centred on the origin ([layout]; `capsflow study` can vary its scalars):
// capsule k = 0 … count − 1 is the mesh moved by (k − (count − 1)/2)·(dx, dy, dz).
struct LayoutSpec {
  LayoutSpec();
  int count;
  double dx, dy, dz;  // centre-to-centre step, in ℓ
};

// One capsule of a [[capsule]] array: its mesh moved to `center` (in ℓ); its own [mesh] and [wall]
// keys where it has any (the scene's sections, with these keys changed), else the scene's.
struct CapsuleSpec {
  Vec3 center = Vec3::Zero();
  std::optional<MeshSpec> mesh;
  std::optional<WallSpec> wall;
};

// Where several capsules meet ([contact]; rhs/suspension_dynamics.hpp, health/surface_gap_watch.hpp).
struct ContactSpec {
  ContactSpec();
  double repulsion_range;     // element sizes; 0: no repulsion
  double repulsion_strength;  // nodal force at zero gap, in μγ̇ℓ²
  double min_gap;             // element sizes: below it the surface_gap condition begins
};

// A straight channel around the capsule ([channel]; docs/channel.md): its shape along x, the
// capsule on its axis unless moved, Poiseuille's flow through it at mean velocity V = 1 (flow.type =
// "poiseuille", Ca_s = μV/G_s).
struct ChannelSpec {
  ChannelSpec();
  ChannelKind shape;          // none: unbounded flow
  double radius;              // tube radius or duct half-width, in ℓ
  double length;              // from inlet to outlet, in ℓ
  double element_size;        // the wall's target edge, in ℓ (resolved from the capsule's under "auto")
  bool element_size_auto = true;
  // constricted_duct, in channel radii: the narrow part's half-height (y) and half-width (z), its
  // length, its centre's x1, and each taper's length ("auto": the wall's element size).
  double constriction_height, constriction_width, constriction_length, constriction_center;
  double constriction_taper;
  bool constriction_taper_auto = true;
  bool active() const { return shape != ChannelKind::None; }
};

struct Scene {
  Scene();                                    // the defaults, resolved (= the scene of an empty file)
  std::string source = "<built-in default>";  // file the scene came from
  std::string toml_text;                      // verbatim input (for metadata)
  MeshSpec mesh;
  WallSpec wall;
  FlowSpec flow;
  TimeSpec time;
  FluidSpec fluid;
  OutputSpec output;
  LayoutSpec layout;
  ContactSpec contact;
  ChannelSpec channel;
  std::vector<CapsuleSpec> capsules;          // [[capsule]] as given; empty: [layout]'s row
  bool wants_field(OutputField f) const;
  // The capsules' centres: the [[capsule]] array, else [layout]'s row ({0, 0, 0} for one capsule:
  // the mesh where it is).
  std::vector<Vec3> capsule_centers() const;
  // Capsule k's own scene: this one with its [mesh] and [wall] keys (Ca_s follows a changed
  // thickness when it is derived from Ca_v).
  Scene capsule_scene(int k) const;
  bool capsules_alike() const;  // no capsule has keys of its own
};

// One key set on the command line: "section.key=value", and the option that gave it, which
// errors name ("--set mesh.level: ...", "--levels mesh.level: ...").
struct SceneOverride {
  std::string assignment;
  std::string option = "--set";
};

// The built-in default scene: a quick, coarse version of the paper's case.
const std::string& default_scene_toml();

// Parse TOML text (name is used in messages), apply "key.path=value" overrides, validate, resolve.
Scene parse_scene(const std::string& toml_text, const std::string& name,
                  const std::vector<std::string>& overrides = {});
// The same with overrides that name the option they came from (a study's --vary and --levels).
Scene parse_scene_with(const std::string& toml_text, const std::string& name, const std::vector<SceneOverride>& overrides);
// Reads a scene file: a missing file, a folder, an unreadable file and an HDF5 or binary file
// each have their own message. A relative mesh.file in the file is resolved against the scene's
// folder (one given with --set against the working directory).
Scene load_scene(const std::string& path, const std::vector<std::string>& overrides = {});
Scene load_scene_with(const std::string& path, const std::vector<SceneOverride>& overrides);

// When Ca_s is derived from Ca_v (flow.ca_s not given), a one-line note that Ca_s = Ca_v/thickness
// moves with the thickness (printed by `capsflow info` and at the start of a run); else "".
std::string capillary_note(const Scene& scene);

// When fluid.fmm_order forces an FMM order but the far field is summed directly (fluid.backend =
// "direct", or "auto" choosing it for a small mesh), a one-line warning that the order is not used
// (printed by `capsflow info` and at the start of a run); else "". A warning, not an error: a study
// may vary the back end with one --set of the order.
std::string unused_fmm_order_note(const Scene& scene, FarFieldBackend used);

nlohmann::json to_json(const Scene& scene);
// Canonical TOML of the resolved scene (every key explicit), for output and restarts.
std::string to_toml(const Scene& scene);

}  // namespace capsflow
