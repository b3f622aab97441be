// THE table of scene keys: every key of a scene file is one row here — its name, its member, its
// default, its accepted values and its doc line (the "meaning" column of docs/scene-and-output.md
// §2, which tests/core/scene/test_scene_keys.cpp keeps equal to this table). Parsing (files and
// --set), validation, to_json, to_toml, `capsflow info` and the docs are all driven by these rows.
// Defaults that a library option struct also needs are taken from that struct, so they live once.
// Rules between keys (ca_s or ca_v, the gradient of each flow type, "auto" schemes, step and output
// counts) are in scene_rules.cpp. To add a key: a member in its section struct (scene.hpp) and one
// row below, in the order to_toml should write it; then paste the docs table the test prints.
#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>

#include "capsflow/core/bie/single_layer.hpp"
#include "capsflow/fmm/calibration.hpp"
#include "capsflow/shell/gsmb_wall.hpp"
#include "key_table.hpp"
#include "scene_rules.hpp"

namespace capsflow {

namespace scene_detail {

namespace {

// A user mesh path, "" for none (then no TOML line). Longer than PATH_MAX it cannot name a file,
// and a 5 MB value must not travel on into the mesh reader's messages.
Key<MeshSpec> mesh_file(std::string meaning) {
  constexpr std::size_t kPathMax = 4096;  // Linux PATH_MAX, the terminating NUL included
  Key<MeshSpec> k = documented<MeshSpec>("file", "string", "path to `.off` / `.ply`", "none", std::move(meaning));
  k.set_default = [](MeshSpec& m) { m.file.clear(); };
  k.read = [](const TomlReader& r, const std::string& sec, MeshSpec& m) {
    if (const std::optional<std::string> v = r.string(sec, "file")) {
      if (v->size() >= kPathMax)
        r.fail(sec, "file", "'" + abbreviate(*v) + "' is longer than a path can be (" + std::to_string(kPathMax - 1) + " bytes)");
      m.file = *v;
    }
  };
  k.to_json = [](const MeshSpec& m) { return nlohmann::json(m.file); };
  k.to_toml = [](const MeshSpec& m) { return m.file.empty() ? std::nullopt : std::optional<std::string>(quoted(m.file)); };
  return k;
}

// The membrane laws by their scene names (shell::to_string); aliases that shell accepts are not
// scene spellings.
Spellings<shell::LawKind> law_spellings() {
  Spellings<shell::LawKind> out;
  for (shell::LawKind k : {shell::LawKind::GeneralizedHooke, shell::LawKind::NeoHookean, shell::LawKind::Skalak,
                           shell::LawKind::MooneyRivlin})
    out.emplace_back(k, shell::to_string(k));
  return out;
}

// A number in `range` or "auto", which sets the flag and puts `when_auto` in the number:
// time.dt (a fixed step, or the scheme's own), time.tolerance and fluid.tolerance.
template <class Spec>
Key<Spec> number_or_auto(const std::string& name, double Spec::*value, bool Spec::*is_auto, const Range<double>& range,
                         const std::string& expected, double when_auto, std::string meaning) {
  Key<Spec> k =
      documented<Spec>(name, "number or `\"auto\"`", range.text() + ", or `\"auto\"`", "`\"auto\"`", std::move(meaning));
  k.set_default = [=](Spec& t) {
    t.*is_auto = true;
    t.*value = when_auto;
  };
  k.read = [=](const TomlReader& r, const std::string& sec, Spec& t) {
    const toml::node* n = r.find(sec, name);
    if (!n) return;
    if (n->is_string()) {
      if (n->as_string()->get() != "auto") r.fail(sec, name, "expected " + expected + " or \"auto\"");
      t.*is_auto = true;
      t.*value = when_auto;
      return;
    }
    const double v = *r.number(sec, name);
    if (!range.contains(v)) r.fail(sec, name, range.out_of_range(v));
    t.*value = v;
    t.*is_auto = false;
  };
  k.to_json = [=](const Spec& t) { return t.*is_auto ? nlohmann::json("auto") : nlohmann::json(t.*value); };
  k.to_toml = [=](const Spec& t) {
    return std::optional<std::string>(t.*is_auto ? quoted("auto") : toml_number(t.*value));
  };
  return k;
}

// time.dt: a positive number (a fixed step) or "auto" (0 in the number).
Key<TimeSpec> time_dt(std::string meaning) {
  return number_or_auto("dt", &TimeSpec::dt, &TimeSpec::dt_auto, above(0.0), "a positive number", 0.0, std::move(meaning));
}

// time.tolerance: a number in [1e-9, 0.1] or "auto", which the time plan resolves for the scheme and
// mesh (stepping/time_plan.hpp); the number then holds 0, read by no one.
Key<TimeSpec> time_tolerance(std::string meaning) {
  const Range<double> range = closed(1e-9, 1e-1).because("units of ℓ");
  return number_or_auto("tolerance", &TimeSpec::tolerance, &TimeSpec::tolerance_auto, range, "a number in " + range.interval(),
                        0.0, std::move(meaning));
}

// fluid.tolerance: a number in [1e-8, 0.1] or "auto" (1e-6 in the number: the direct sums' and the
// crossover's), resolved with the time keys by far_field_tolerance (scene/boundary_integral_options.hpp).
// The boundary integral asks the FMM for 0.25 × the tolerance (its floor is 1e-10,
// fmm/calibration.hpp), and its direct far field is accurate to ~1e-9 (single_layer.cpp).
Key<FluidSpec> fluid_tolerance(std::string meaning) {
  const Range<double> range = closed(1e-8, 1e-1).because("the far-field sums are accurate to ~1e-9");
  return number_or_auto("tolerance", &FluidSpec::tolerance, &FluidSpec::tolerance_auto, range,
                        "a number in " + range.interval(), SingleLayerOptions{}.tolerance, std::move(meaning));
}

// flow.ca_v: written to TOML only as the comment on ca_s's line (one of the two is the input).
Key<FlowSpec> flow_ca_v(std::string meaning) {
  Key<FlowSpec> k = number("ca_v", &FlowSpec::ca_v, 0.003, above(0.0), std::move(meaning));
  k.alternative = "ca_s";
  k.to_toml = [](const FlowSpec&) { return std::optional<std::string>(); };
  return k;
}

// flow.ca_s: when given, ca_v follows from it; otherwise it follows from ca_v (scene_rules.cpp).
Key<FlowSpec> flow_ca_s(std::string meaning) {
  Key<FlowSpec> k = number("ca_s", &FlowSpec::ca_s, 0.0, capillary_range(), std::move(meaning));
  k.alternative = "ca_v";
  k.default_text = [] { return std::string("derived: ca_v/thickness"); };
  k.set_default = [](FlowSpec& f) {
    f.ca_s_from_ca_v = true;
    f.ca_s = std::numeric_limits<double>::quiet_NaN();  // until the thickness is known (Scene(), parse_scene)
  };
  k.read = [read = k.read](const TomlReader& r, const std::string& sec, FlowSpec& f) {
    read(r, sec, f);
    if (r.has(sec, "ca_s")) f.ca_s_from_ca_v = false;
  };
  k.to_toml = [](const FlowSpec& f) {
    return std::optional<std::string>(toml_number(f.ca_s) + "  # ca_v = ca_s * thickness = " + toml_number(f.ca_v));
  };
  return k;
}

// flow.gradient: L of v∞ = L x, given only with type = "linear" (scene_rules.cpp); resolved for
// every type, so JSON always has it.
Key<FlowSpec> flow_gradient(std::string meaning) {
  Key<FlowSpec> k = documented<FlowSpec>("gradient", "3×3 array of numbers", "finite, trace-free", "—", std::move(meaning));
  k.set_default = [](FlowSpec& f) { f.gradient.setZero(); };
  k.read = [](const TomlReader& r, const std::string& sec, FlowSpec& f) {
    if (const std::optional<Mat3> g = r.matrix3(sec, "gradient")) {
      if (!(std::abs(g->trace()) <= 1e-12 * std::max(1.0, g->norm())))
        r.fail(sec, "gradient", "must be trace-free (incompressible flow)");
      f.gradient = *g;
    }
  };
  k.to_json = [](const FlowSpec& f) {
    nlohmann::json g = nlohmann::json::array();
    for (int i = 0; i < 3; ++i) g.push_back({f.gradient(i, 0), f.gradient(i, 1), f.gradient(i, 2)});
    return g;
  };
  k.to_toml = [](const FlowSpec& f) {
    if (f.type != FlowType::Linear) return std::optional<std::string>();
    const Mat3& g = f.gradient;
    return std::optional<std::string>(fmt::format("[[{}, {}, {}], [{}, {}, {}], [{}, {}, {}]]", g(0, 0), g(0, 1), g(0, 2),
                                                  g(1, 0), g(1, 1), g(1, 2), g(2, 0), g(2, 1), g(2, 2)));
  };
  return k;
}

}  // namespace

const Range<double>& capillary_range() {
  // Ca_s is the elastic time μℓ/G_s over the flow time 1/γ̇. At 1e-6 the wall is stiff enough for
  // 6.6e7 Heun steps to γ̇t = 2 at 1280 elements (`capsflow info`), and a run still stops cleanly;
  // at 1e-300 the forces overflowed (NaN in the mass-matrix solve, exit 1). Above 1e6 the
  // membrane's response is slower than any run can follow.
  static const Range<double> r =
      closed(1e-6, 1e6).because("Ca_s = μγ̇ℓ/G_s, the elastic over the flow time scale; beyond, one is a million times the other");
  return r;
}

const Section<MeshSpec>& mesh_keys() {
  static const Section<MeshSpec> s{
      "mesh", &Scene::mesh,
      {choice("base", &MeshSpec::base, BaseSolid::Icosahedron, "base solid (`docs/conventions.md` §4.1)"),
       integer("level", &MeshSpec::level, 4, closed(0, 9), "subdivisions: 20·4^level or 8·4^level elements"),
       choice("shape", &MeshSpec::shape, MeshShape::Spheroid,
              "`\"sphere\"` forces `aspect = 1`; `\"biconcave\"`: the red blood cell's resting disc (Evans & Fung 1972, "
              "`docs/conventions.md` §4.2.1), `aspect` unused"),
       number("aspect", &MeshSpec::aspect, 1.4, closed(0.1, 10.0), "a/b of the spheroid (> 1 prolate, < 1 oblate)"),
       integer("axis", &MeshSpec::axis, 3, closed(1, 3), "symmetry axis of the spheroid or the biconcave disc"),
       mesh_file("user mesh; when given, `base`, `level`, `shape`, `aspect`, `axis` are ignored (still validated). A "
                 "relative path in a scene file is relative to the scene's folder; given with `--set`, relative to the "
                 "working directory (`docs/conventions.md` §4.4)")}};
  return s;
}

const Section<WallSpec>& wall_keys() {
  const shell::GsmbOptions gsmb;  // the shell's defaults
  static const Section<WallSpec> s{
      "wall", &Scene::wall,
      {choice("model", &WallSpec::model, WallModel::Gsmb, "membrane only, or MITC3 GSMB shell (`docs/shell.md` §2.2)"),
       choice("law", &WallSpec::law, shell::LawKind::GeneralizedHooke,
              "membrane law (`docs/shell.md` §2.3); `\"mr\"` is Mooney–Rivlin", law_spellings()),
       number("thickness", &WallSpec::thickness, gsmb.thickness, open_closed(0.0, 0.5).because("h/ℓ"), "α = h/ℓ"),
       number("poisson", &WallSpec::poisson, gsmb.poisson, open(-1.0, 1.0),
              "ν_s of GH; ν of the GSMB bending and shear terms (any law)"),
       number("skalak_c", &WallSpec::skalak_c, 1.0, above(0.0), "Skalak area parameter C"),
       number("mooney_rivlin_psi", &WallSpec::mooney_rivlin_psi, 0.1, closed(0.0, 1.0),
              "Mooney–Rivlin Ψ = C2/(C1 + C2) (0 is neo-Hookean)"),
       integer("max_newton", &WallSpec::max_newton, gsmb.max_newton, closed(1, 1000),
               "GSMB: iteration cap of the rotation Newton solve (usually 1–4 are used; up to 47 measured where a fold "
               "makes the rotation equilibrium a saddle, `docs/shell.md` §2.8); a solve that does not converge is retried "
               "once from the nodal normals; then, under error control, the step is tried again a quarter as long (three "
               "times at most), and otherwise the run stops with `solver_failure`"),
       number("prestress", &WallSpec::prestress, 0.0,
              closed(0.0, 0.5).because("the initial stretch 1 + α_p, with room for the flow's, within the stretches 0.7–2.1 "
                                       "at which the laws are tested"),
              "pre-inflation α_p: the wall's stress-free shape is the initial one shrunk by 1 + α_p about its centroid, so "
              "the capsule starts inflated and under tension (as in Lac, Morel & Barthès-Biesel 2007; `docs/shell.md` "
              "§2.10); any model, law and flow; 0: the initial shape is stress-free"),
       number("initial_stretch", &WallSpec::initial_stretch, 1.0,
              closed(1.0, 2.0).because("a stretch of 2 narrows the capsule by 1/√2, enough for confinements up to 1.4"),
              "the capsule starts stretched along x1 by this factor and narrowed across by its square root (its volume "
              "kept) about its centroid, its wall's stress-free shape being the mesh's (shrunk by 1 + `prestress`): a "
              "capsule wider than a channel starts inside it (`docs/shell.md` §2.10); 1: the mesh's shape")}};
  return s;
}

const Section<FlowSpec>& flow_keys() {
  static const Section<FlowSpec> s{
      "flow", &Scene::flow,
      {choice("type", &FlowSpec::type, FlowType::PlanarHyperbolic,
              "imposed flow (`docs/conventions.md` §3); `poiseuille`: through a `[channel]` at mean velocity V, "
              "which then stands for γ̇ℓ in every unit (Ca_s = μV/G_s, time in ℓ/V; `docs/channel.md`)"),
       flow_ca_v("Ca_v = μγ̇/G; then ca_s = ca_v/thickness, which must lie in " + capillary_range().interval()),
       flow_ca_s("Ca_s = μγ̇ℓ/G_s; then ca_v = ca_s·thickness"),
       flow_gradient("L of v∞ = L x; required with `type = \"linear\"`, refused otherwise")}};
  return s;
}

const Section<TimeSpec>& time_keys() {
  static const Section<TimeSpec> s{
      "time", &Scene::time,
      {choice("scheme", &TimeSpec::scheme, TimeScheme::Auto, "Heun at the stability-limited step (§5.5, §5.9), damped RKC2 with error control "
                   "(`docs/time-integration.md` §5.6), or `\"rock4\"`: a fourth-order stabilised scheme with error "
                   "control (§5.8); `\"auto\"`: with `dt = \"auto\"`, ROCK4 where the wall's analytic spectral radius on the "
                   "reference mesh is below 800 flow rates (soft for its mesh: accuracy sets the step) and RKC2 "
                   "above (stability does), with a fixed `dt` RKC2 (§5.2; the log and `capsflow info` say which)"),
       time_tolerance("RKC: local error per step, RMS over nodes, in units of ℓ (§5.6); `\"auto\"`: 1e-5, and if the "
                      "wall creases at the mesh scale the run starts again from t = 0 at 5e-7 up to the creases, 1e-5 "
                      "after (§5.3; keeps D_ij within 1e-4 of the time-converged result on the paper's cases); with ROCK4 the "
                      "estimate is that of its embedded third-order solution with the grid-scale modes filtered out, and "
                      "`\"auto\"` is 2e-3 × 1280/N for N elements (a plain membrane: 2e-3 × (1280/N)^(8/3)) from "
                      "t = 0, and 2e-3 (or that value, if looser) once the run sees the wall crease, no rewind (§5.8, §5.4)"),
       time_dt("fixed step; `\"auto\"`: Heun takes `dt_safety` × the stability limit recomputed every step "
               "(`docs/time-integration.md` §5.9), RKC its error-controlled step; a fixed step may need at most " +
                   number_text(kMaxSteps) + " steps to `t_end`"),
       // 0.8: the calibrated limit is a measured bound with 18 % to spare on the worst calibration case
       // (c_m = 1.15 measured against 1.4 used, docs/time-integration.md §5.9.3); above, a step is no
       // longer known to be stable (dt_safety = 1.4 loses 3 % of the volume and half of D13). 1e-3
       // takes 700× the steps of the default for no stability to gain: below it (1e-300 was
       // accepted) the count of an automatic step, unknown when the scene is read, is unbounded.
       number("dt_safety", &TimeSpec::dt_safety, 0.7,
              closed(1e-3, 0.8).because("0.8: the largest fraction of the calibrated limit measured stable"),
              "Heun: fraction of the limit used by `\"auto\"`; 0.8 is the largest fraction measured stable on the "
              "calibration cases (§5.9.3)"),
       number("t_end", &TimeSpec::t_end, 5.0, above(0.0), "final γ̇t"),
       boolean("stop_at_steady", &TimeSpec::stop_at_steady, false,
               "stop when the steady-state test holds (`docs/time-integration.md` §5.11)"),
       number("steady_tol", &TimeSpec::steady_tol, 5e-4, above(0.0), "area change over γ̇t = 1, relative to 4πℓ²"),
       choice_list("stop_on", &TimeSpec::stop_on,
                   "stop (exit 3, `stop_reason` = the name) when one of these health conditions begins "
                   "(`docs/health-monitors.md`); each is warned about once per episode either way; a name given twice "
                   "counts once")}};
  return s;
}

const Section<FluidSpec>& fluid_keys() {
  const SingleLayerOptions bie;  // the boundary integral's defaults
  // The calibrated orders (fmm/calibration.hpp); 0 keeps the order the tolerance calls for.
  const int lowest = std::begin(fmm::kCalibration)->order, highest = std::prev(std::end(fmm::kCalibration))->order;
  static const Section<FluidSpec> s{
      "fluid", &Scene::fluid,
      {choice("backend", &FluidSpec::backend, bie.backend, "far-field summation (`docs/boundary-integral.md` §4.3)"),
       fluid_tolerance("far-field accuracy relative to max‖v‖: sets the FMM order, and from 1e-5 on lets the direct sum "
                       "use single-precision pairs; `\"auto\"`: 1e-6 for direct sums and the back-end crossover, 1e-5 for "
                       "the single layer's FMM where error control sets the step (never looser than a given "
                       "`time.tolerance`), 1e-6 at λ ≠ 1 or without error control; keeps D_ij within 2.1e-5 of a 1e-8 far "
                       "field on the paper's cases (`docs/boundary-integral.md` §4.3.2)"),
       choice("geometry", &FluidSpec::geometry, bie.geometry,
              "surface seen by the boundary integral (`docs/boundary-integral.md` §4.5)"),
       choice("far_rule", &FluidSpec::far_rule, bie.far_rule,
              "far-field sources (`docs/boundary-integral.md` §4.2.1): `\"auto\"` takes one per edge midpoint on flat facets "
              "(3 per node) and three Gauss points per element on curved ones (6 per node); `\"gauss_points\"` on flat "
              "facets is the former 6-per-node far field, kept to measure the edge-midpoint rule against it"),
       boolean("volume_correction", &FluidSpec::volume_correction, true,
               "remove the discrete net flux at every stage (`docs/time-integration.md` §5.10)"),
       integer("fmm_order", &FluidSpec::fmm_order, bie.fmm_order,
               closed(lowest, highest).or_value(0).because("0: the order follows from fluid.tolerance"),
               "0: the FMM order follows from `tolerance` (`fmm/calibration.hpp`); otherwise that order is forced (to "
               "measure accuracy against cost, or to show that `verify_every` catches a too-low order); the direct sum has "
               "no order: with it a forced order is unused, and `info` and the run say so"),
       integer("fmm_leaf_size", &FluidSpec::fmm_leaf_size, bie.fmm_leaf_size,
               closed(16, 1000000).or_value(0).because("0: the calibrated leaf; fewer than 16 points per leaf only cost"),
               "0: the FMM's points per leaf follow from its order (`fmm/calibration.hpp`, measured at the boundary "
               "integral's sizes); otherwise that many: a box is split while it holds more sources or more targets "
               "(to tune the FMM on another machine, or to force a deep tree on a small mesh); unused by the direct sum"),
       // 1e6 evaluations between checks is as good as none (and keeps the count an int).
       integer("verify_every", &FluidSpec::verify_every, bie.verify_every,
               closed(0, 1000000).because("right-hand-side evaluations between direct checks; 0 = off"),
               "direct check of the far field: every N right-hand-side evaluations (the first one included) the far "
               "field is also summed directly, in full double precision, on the same sources and nodes (with "
               "`viscosity_ratio` ≠ 1 the double layer's too); 0 = off (then nothing is computed and no column or key is "
               "added)"),
       // λ = 1e-6 and 1e6 already behave as the bubble and rigid limits (docs/boundary-integral.md §4.8.2).
       number("viscosity_ratio", &FluidSpec::viscosity_ratio, 1.0,
              closed(1e-6, 1e6).because("λ = inner/outer viscosity; beyond, the bubble and rigid limits"),
              "λ = viscosity inside / outside; λ = 1: the single layer alone (the code path and numbers of a scene "
              "without the key); otherwise the second-kind equation (1 + λ)/2 u + (1 − λ) D[u] = v∞ − S[q] solved by "
              "deflated GMRES at every evaluation (`docs/boundary-integral.md` §4.8); the double layer's far field "
              "follows `backend` (FMM or direct sum; `\"auto\"` by the stresslet FMM's own crossover)"),
       // 10× the coldest solve measured (≤ 10 iterations on spheres and a/b = 2 spheroids, λ = 0.01–100).
       integer("max_gmres", &FluidSpec::max_gmres, 100, closed(1, 10000),
               "λ ≠ 1: iteration cap of the second-kind GMRES solve (1–3 are used per evaluation, ≤ 10 from a cold "
               "start, `docs/boundary-integral.md` §4.8.3); a solve that does not reach its tolerance stops the run "
               "with `solver_failure`"),
       boolean("reuse_identity_term", &FluidSpec::reuse_identity_term, true,
               "λ ≠ 1, flat facets, FMM back end: the double layer's D̃[1] is the polyhedron's exact corner value plus "
               "its quadrature error, which is computed by a full far-field pass only on refreshing set-ups and reused "
               "between them, extrapolated from the last two or three refreshes, and refreshed when its drift, measured every "
               "evaluation at about 512 nodes by direct sums, exceeds half of a quarter of `tolerance` "
               "(`docs/boundary-integral.md` §4.7.5); false: the full pass on every evaluation (to measure the reuse against)")}};
  return s;
}

const Section<OutputSpec>& output_keys() {
  static const Section<OutputSpec> s{
      "output", &Scene::output,
      {number("every", &OutputSpec::every, 0.1, above(0.0),
              "output interval in γ̇t (Heun's and fixed time steps are shortened to land on it; error-controlled RKC writes it from its dense output); at most " + number_text(kMaxOutputs) +
                  " outputs to `time.t_end`"),
       choice_list("fields", &OutputSpec::fields, "nodal fields stored per output step (§3.2); a name given twice counts once"),
       number("checkpoint_every", &OutputSpec::checkpoint_every, 0.5, at_least(0.0),
              "checkpoint interval in γ̇t; 0 = only the final checkpoint; at most " + number_text(kMaxOutputs) +
                  " checkpoints to `time.t_end`")}};
  return s;
}

const Section<LayoutSpec>& layout_keys() {
  const std::string step = "centre-to-centre step from one capsule of the row to the next, in ℓ; ";
  static const Section<LayoutSpec> s{
      "layout", &Scene::layout,
      {integer("count", &LayoutSpec::count, 1, closed(1, kMaxCapsules),
               "capsules in a row centred on the origin, capsule k (0-based) moved by (k − (count − 1)/2)·(dx, dy, dz) "
               "(`docs/several-capsules.md`); 1: one capsule where its mesh is; give either this or `[[capsule]]` tables"),
       number("dx", &LayoutSpec::dx, 0.0, Range<double>{}, step + "x1 component (a pair offset in shear: dx = −4, dy = 0.5)"),
       number("dy", &LayoutSpec::dy, 0.0, Range<double>{}, step + "x2 component"),
       number("dz", &LayoutSpec::dz, 0.0, Range<double>{}, step + "x3 component (a train along the x3 axis)")}};
  return s;
}

const Section<ContactSpec>& contact_keys() {
  static const Section<ContactSpec> s{
      "contact", &Scene::contact,
      {number("repulsion_range", &ContactSpec::repulsion_range, 0.0,
              closed(0.0, 3.0).because("element sizes; the cross-surface search reaches 3"),
              "several capsules: a node closer than this many element sizes to an element of another capsule is pushed "
              "away with the force `repulsion_strength`·(1 − d/(range h))², its reaction on that element (force- and "
              "torque-free; `docs/several-capsules.md`); 0 = off"),
       number("repulsion_strength", &ContactSpec::repulsion_strength, 1.0, at_least(0.0),
              "nodal force of the repulsion at zero gap, in μγ̇ℓ²"),
       number("min_gap", &ContactSpec::min_gap, 0.05,
              at_least(0.0).because("element sizes"),
              "several capsules, or a capsule in a channel: the `surface_gap` health condition begins when the "
              "smallest gap between two capsules (or a capsule and the channel's wall) falls below this many element sizes (the near-singular quadrature is measured down to 0.05, "
              "`docs/boundary-integral.md` §4.9); with `time.stop_on = [\"surface_gap\"]` the run stops there")}};
  return s;
}

const Section<ChannelSpec>& channel_keys() {
  static const Section<ChannelSpec> s{
      "channel", &Scene::channel,
      {choice("shape", &ChannelSpec::shape, ChannelKind::None,
              "a channel along x1 around the capsule (`docs/channel.md`): `tube` (circular), `square_duct`, or "
              "`constricted_duct` (the square duct narrowed over a short length, the `constriction_*` keys; the run is "
              "in the lab frame and ends before the capsule reaches the outlet), closed by an inlet and an outlet cap, "
              "with Poiseuille's flow through it (`flow.type = \"poiseuille\"`, required with a channel and only with "
              "one); `none`: unbounded flow"),
       number("radius", &ChannelSpec::radius, 1.25, above(0.0),
              "tube radius or duct half-width, in ℓ (1.25: confinement ℓ/radius = 0.8); the capsule must start inside it"),
       number("length", &ChannelSpec::length, 10.0, above(0.0),
              "from inlet to outlet, in ℓ; at least the capsule's length along x1 plus 4 radii, so that the capsule's "
              "disturbance has decayed at the caps (`docs/channel.md` §3.1)"),
       number_or_auto("element_size", &ChannelSpec::element_size, &ChannelSpec::element_size_auto, above(0.0),
                      "a positive number", 0.0,
                      "the wall's target edge length, in ℓ; `\"auto\"`: the capsule's mean edge, but not finer than "
                      "radius/8 (`docs/channel.md` §4); at most 4 times the capsule's mean edge"),
       number("constriction_height", &ChannelSpec::constriction_height, 0.5, open_closed(0.0, 1.0),
              "constricted_duct: the narrow part's half-height along x2, in channel radii (0.5: Park & Dimitrakopoulos "
              "2013's constriction, as high as a capsule of radius radius/2)"),
       number("constriction_width", &ChannelSpec::constriction_width, 1.0, open_closed(0.0, 1.0),
              "constricted_duct: the narrow part's half-width along x3, in channel radii (1: not narrowed along x3)"),
       number("constriction_length", &ChannelSpec::constriction_length, 1.0, at_least(0.0),
              "constricted_duct: the narrow part's length along x1, in channel radii"),
       number("constriction_center", &ChannelSpec::constriction_center, 2.0, Range<double>{},
              "constricted_duct: x1 of the narrow part's middle, in channel radii (the capsule starts where its mesh is); "
              "the constriction and its tapers must end at least 2 radii from each cap and clear the capsule's start"),
       number_or_auto("constriction_taper", &ChannelSpec::constriction_taper, &ChannelSpec::constriction_taper_auto,
                      above(0.0), "a positive number", 0.0,
                      "constricted_duct: the length along x1 of each straight taper from the duct to the narrow part, in "
                      "channel radii; `\"auto\"`: one wall element, the steepest step the wall's mesh resolves")}};
  return s;
}

}  // namespace scene_detail

// Each section struct starts from the table's defaults.
namespace {
template <class Spec>
void set_defaults(const scene_detail::Section<Spec>& section, Spec& spec) {
  for (const auto& k : section.keys) k.set_default(spec);
}
}  // namespace

MeshSpec::MeshSpec() { set_defaults(scene_detail::mesh_keys(), *this); }
WallSpec::WallSpec() { set_defaults(scene_detail::wall_keys(), *this); }
FlowSpec::FlowSpec() { set_defaults(scene_detail::flow_keys(), *this); }
TimeSpec::TimeSpec() { set_defaults(scene_detail::time_keys(), *this); }
FluidSpec::FluidSpec() { set_defaults(scene_detail::fluid_keys(), *this); }
OutputSpec::OutputSpec() { set_defaults(scene_detail::output_keys(), *this); }
LayoutSpec::LayoutSpec() { set_defaults(scene_detail::layout_keys(), *this); }
ContactSpec::ContactSpec() { set_defaults(scene_detail::contact_keys(), *this); }
ChannelSpec::ChannelSpec() { set_defaults(scene_detail::channel_keys(), *this); }

}  // namespace capsflow
