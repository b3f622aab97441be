// The run's output: run.h5, run.xmf, timeseries.csv, summary.json (see results_writer.hpp).
#include "capsflow/core/io/results_writer.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <ctime>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>

#include "capsflow/core/io/atomic_file.hpp"
#include "capsflow/core/io/h5.hpp"
#include "capsflow/core/io/io_error.hpp"

namespace capsflow::io {
namespace fs = std::filesystem;

struct ResultsWriter::State {
  fs::path folder;
  Eigen::Index num_nodes = 0;
  Eigen::Index num_triangles = 0;
  MeshParts parts;                   // K + 1 offsets each, K >= 1 (see parts())
  std::vector<XdmfStep> steps;       // in time order; mirrors /steps in run.h5
  std::int64_t next_index = 0;       // k of the next /steps/<k>
  std::optional<TimeseriesCsv> csv;  // opened on the first row
  bool run_file_rebuilt = false;     // reopen: run.h5 held a damaged object and was rebuilt

  fs::path h5_path() const { return folder / kRunH5; }
};

namespace {

// Indented JSON; invalid UTF-8 (a file name from the command line) is replaced, never thrown.
std::string dump_json(const nlohmann::json& j) {
  return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace);
}

// "2026-11-22T02:50:00Z": when the run file was made (with the host, for reproducibility).
std::string utc_now() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

std::string host_name() {
  char buf[256] = {};
  return ::gethostname(buf, sizeof buf - 1) == 0 ? std::string(buf) : std::string("unknown");
}

std::string step_group(std::int64_t k) { return fmt::format("/steps/{:06d}", k); }

// One part spanning the whole mesh: a run of one surface.
MeshParts whole_mesh(Eigen::Index num_nodes, Eigen::Index num_triangles) {
  return {{0, std::int64_t(num_nodes)}, {0, std::int64_t(num_triangles)}};
}

// check_mesh_parts, and every triangle of capsule k uses only nodes of capsule k (so that its
// local indices, triangles minus the capsule's first node, index the capsule's own rows).
void check_parts_of(const MeshParts& parts, const SurfaceMesh& mesh) {
  check_mesh_parts(parts, mesh.num_nodes(), mesh.num_elements());
  for (std::size_t k = 0; k + 1 < parts.nodes.size(); ++k) {
    const std::int64_t first = parts.nodes[k], end = parts.nodes[k + 1];
    for (std::int64_t i = parts.elements[k]; i < parts.elements[k + 1]; ++i) {
      for (int c = 0; c < 3; ++c) {
        const std::int64_t v = mesh.triangles(Eigen::Index(i), c);
        if (v < first || v >= end) {
          throw std::invalid_argument(fmt::format(
              "mesh parts: triangle {} of capsule {} (triangles [{}, {})) uses node {}, outside the "
              "capsule's nodes [{}, {})",
              i, k + 1, parts.elements[k], parts.elements[k + 1], v, first, end));
        }
      }
    }
  }
}

// /mesh/parts/local_triangles: the union's triangles, each capsule's less its first node.
h5::RowMatrixXi local_triangles(const MeshParts& parts, const Triangles& triangles) {
  h5::RowMatrixXi local = triangles;
  for (std::size_t k = 0; k + 1 < parts.nodes.size(); ++k) {
    const Eigen::Index first = Eigen::Index(parts.elements[k]);
    const Eigen::Index count = Eigen::Index(parts.elements[k + 1]) - first;
    local.middleRows(first, count).array() -= int(parts.nodes[k]);
  }
  return local;
}

std::vector<std::int64_t> to_std(const Eigen::Matrix<std::int64_t, Eigen::Dynamic, 1>& v) {
  return std::vector<std::int64_t>(v.data(), v.data() + v.size());
}

// HDF5 link names cannot contain '/', and "." is the object itself.
std::string link_name(std::string key) {
  std::replace(key.begin(), key.end(), '/', '_');
  return key.empty() || key == "." ? "_" : key;
}

void write_metadata(h5::Group& g, const nlohmann::json& metadata) {
  if (!metadata.is_object()) {
    throw std::invalid_argument("output metadata must be a JSON object, got " +
                                std::string(metadata.type_name()));
  }
  for (const auto& [key, value] : metadata.items()) {
    const std::string name = link_name(key);
    if (value.is_string()) {
      g.write_string(name, value.get<std::string>());
    } else if (value.is_boolean()) {
      g.set_attribute(name, std::int64_t(value.get<bool>() ? 1 : 0));
    } else if (value.is_number_integer()) {
      g.set_attribute(name, value.get<std::int64_t>());
    } else if (value.is_number_float()) {
      g.set_attribute(name, value.get<double>());
    } else {
      g.write_string(name, dump_json(value));
    }
  }
}

// Numeric leaves of a JSON tree as float64 attributes named by their dotted key path.
void flatten_numbers(h5::Group& g, const nlohmann::json& j, const std::string& prefix) {
  if (j.is_number()) {
    g.set_attribute(prefix.empty() ? "value" : prefix, j.get<double>());
  } else if (j.is_object()) {
    for (const auto& [key, value] : j.items()) {
      flatten_numbers(g, value, prefix.empty() ? key : prefix + "." + key);
    }
  }
}

// What a restart keeps of run.h5 and what it drops (ResultsWriter::reopen).
struct RunFileSurvey {
  Eigen::Index num_triangles = 0;
  Eigen::Index num_nodes = 0;
  MeshParts parts;                                       // from /mesh/parts, else the whole mesh
  std::string csv_header;
  std::map<std::int64_t, std::string> csv_rows;          // by step index
  std::vector<std::pair<std::int64_t, XdmfStep>> kept;  // the steps up to the restart time, in order
  std::vector<std::string> kept_profiles;               // /profiles/<k> of the kept steps
  std::vector<std::string> dropped;                     // later steps and profiles
  bool damaged = false;                                 // something to drop cannot be read
};

bool all_digits(const std::string& name) {
  return !name.empty() && name.find_first_not_of("0123456789") == std::string::npos;
}

// A step kept by the restart: its time and fields, its CSV row into `csv_rows`.
XdmfStep kept_step(const h5::Group& g, std::int64_t k, double t, Eigen::Index num_nodes,
                   std::map<std::int64_t, std::string>& csv_rows) {
  if (g.has_attribute("csv_row")) csv_rows.emplace(k, g.attribute_string("csv_row"));
  XdmfStep st{t, step_group(k), {}};
  for (const std::string& field : g.children()) {
    if (field == "positions") continue;
    const std::vector<hsize_t> dims = g.shape(field);
    const int comps = dims.size() == 1 ? 1 : int(dims[1]);
    st.fields.push_back({field, comps, !dims.empty() && Eigen::Index(dims[0]) != num_nodes});
  }
  return st;
}

// Reads run.h5 without changing it. A step or profile that cannot be read is one the killed run
// was writing, after every step it completed: one before a kept step is an error.
RunFileSurvey survey_run_file(const h5::File& f, const std::string& path, double t_restart) {
  RunFileSurvey s;
  const std::vector<hsize_t> tri = f.shape("mesh/triangles");
  const std::vector<hsize_t> ref = f.shape("mesh/reference_positions");
  if (tri.size() != 2 || tri[1] != 3 || ref.size() != 2 || ref[1] != 3) {
    throw IoError("'" + path + "' is not a capsflow run file: /mesh has unexpected shapes");
  }
  s.num_triangles = Eigen::Index(tri[0]);
  s.num_nodes = Eigen::Index(ref[0]);
  s.parts = whole_mesh(s.num_nodes, s.num_triangles);
  if (f.exists("mesh/parts")) {
    MeshParts parts{to_std(f.read_vector<std::int64_t>("mesh/parts/node_offsets")),
                    to_std(f.read_vector<std::int64_t>("mesh/parts/element_offsets"))};
    try {
      check_mesh_parts(parts, s.num_nodes, s.num_triangles);
    } catch (const std::invalid_argument& e) {
      throw IoError("'" + path + "': /mesh/parts does not match /mesh: " + e.what());
    }
    if (f.shape("mesh/parts/local_triangles") != tri) {
      throw IoError("'" + path +
                    "': /mesh/parts/local_triangles and /mesh/triangles differ in shape");
    }
    if (parts.nodes.size() > 2) s.parts = std::move(parts);
  }
  std::map<std::int64_t, XdmfStep> kept;
  std::vector<std::int64_t> unreadable;
  if (f.exists("steps")) {
    const h5::Group steps = f.open_group("steps");
    if (steps.has_attribute("csv_header")) s.csv_header = steps.attribute_string("csv_header");
    for (const std::string& name : steps.children()) {
      if (!all_digits(name)) {
        throw IoError("'" + path + "': unexpected group /steps/" + name + " (not written by capsflow?)");
      }
      const std::int64_t k = std::stoll(name);
      try {
        const h5::Group g = steps.open_group(name);
        const double t = g.attribute_double("time");
        if (t <= t_restart) kept.emplace(k, kept_step(g, k, t, s.num_nodes, s.csv_rows));
        else s.dropped.push_back(step_group(k));
      } catch (const IoError&) {
        unreadable.push_back(k);
      }
    }
  }
  for (const std::int64_t k : unreadable) {
    if (!kept.empty() && k < kept.rbegin()->first) {
      throw IoError(fmt::format("'{}': {} was written before the restart time and cannot be read", path,
                                step_group(k)));
    }
    s.dropped.push_back(step_group(k));
    s.damaged = true;
  }
  if (f.exists("profiles")) {
    const h5::Group profiles = f.open_group("profiles");
    for (const std::string& name : profiles.children()) {
      if (!all_digits(name)) {
        throw IoError("'" + path + "': unexpected group /profiles/" + name + " (not written by capsflow?)");
      }
      const bool keep = std::stoull(name) < kept.size();  // profile k belongs to the k-th step
      (keep ? s.kept_profiles : s.dropped).push_back("/profiles/" + name);
      try {
        profiles.open_group(name).attribute_double("time");
      } catch (const IoError&) {
        if (keep) throw IoError("'" + path + "': /profiles/" + name + " was written before the restart time and cannot be read");
        s.damaged = true;
      }
    }
  }
  for (auto& [k, st] : kept) s.kept.emplace_back(k, std::move(st));
  return s;
}

// Replaces run.h5 by a copy of what the restart keeps: the mesh (the whole group, /mesh/parts
// included), the metadata, the kept steps with the CSV header and their profiles (the timing
// table is written again at the run's end).
void rebuild_run_file(const fs::path& path, const RunFileSurvey& s) {
  const h5::File from = h5::File::open(path, h5::File::Mode::read_only, true);
  replace_file_atomically(path, [&](const fs::path& tmp) {
    h5::File to = h5::File::create(tmp);
    for (const char* top : {"mesh", "metadata"}) from.copy_to(top, to, top);
    {
      h5::Group steps = to.create_group("steps");
      if (!s.csv_header.empty()) steps.set_attribute("csv_header", s.csv_header);
    }
    for (const auto& [k, st] : s.kept) from.copy_to(st.group, to, st.group);
    for (const std::string& name : s.kept_profiles) from.copy_to(name, to, name);
    to.close();
  });
}

}  // namespace

ResultsWriter::ResultsWriter(std::unique_ptr<State> s) : s_(std::move(s)) {}
ResultsWriter::ResultsWriter(ResultsWriter&&) noexcept = default;
ResultsWriter& ResultsWriter::operator=(ResultsWriter&&) noexcept = default;
ResultsWriter::~ResultsWriter() = default;

ResultsWriter::ResultsWriter(fs::path folder, const SurfaceMesh& reference_mesh,
                             const nlohmann::json& metadata, MeshParts parts)
    : s_(std::make_unique<State>()) {
  s_->folder = std::move(folder);
  s_->num_nodes = reference_mesh.num_nodes();
  s_->num_triangles = reference_mesh.num_elements();
  if (s_->num_nodes == 0 || s_->num_triangles == 0) {
    throw std::invalid_argument("ResultsWriter: the reference mesh is empty");
  }
  try {
    check_parts_of(parts, reference_mesh);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("ResultsWriter: ") + e.what());
  }
  // One part is the whole mesh: the layout of one surface, without /mesh/parts.
  const bool several = parts.num_parts() > 1;
  s_->parts = several ? std::move(parts) : whole_mesh(s_->num_nodes, s_->num_triangles);
  // A new run starts new series: never append to a CSV or keep a summary of an earlier run.
  for (const char* stale : {kTimeseriesCsv, kSummaryJson}) {
    std::error_code ec;
    fs::remove(s_->folder / stale, ec);
  }
  // Written to a temporary and renamed, so a crash here never leaves a half-made run.h5.
  replace_file_atomically(s_->h5_path(), [&](const fs::path& tmp) {
    h5::File f = h5::File::create(tmp);
    f.write_matrix("mesh/triangles", reference_mesh.triangles);
    f.write_matrix("mesh/reference_positions", reference_mesh.vertices);
    if (several) {
      const MeshParts& p = s_->parts;
      using Offsets = Eigen::Map<const Eigen::Matrix<std::int64_t, Eigen::Dynamic, 1>>;
      f.write_vector("mesh/parts/node_offsets",
                     Offsets(p.nodes.data(), Eigen::Index(p.nodes.size())));
      f.write_vector("mesh/parts/element_offsets",
                     Offsets(p.elements.data(), Eigen::Index(p.elements.size())));
      f.write_matrix("mesh/parts/local_triangles", local_triangles(p, reference_mesh.triangles));
    }
    {
      h5::Group meta = f.create_group("metadata");
      write_metadata(meta, metadata);
      meta.set_attribute("schema_version", kOutputSchemaVersion);
      meta.set_attribute("hdf5_version", h5::library_version());
      meta.set_attribute("created_utc", utc_now());
      meta.set_attribute("hostname", host_name());
    }
    f.create_group("steps");
    f.close();  // every object handle is closed by now, so this really closes the file
  });
  rewrite_xdmf();  // removes a run.xmf left by an earlier run in this folder
}

ResultsWriter ResultsWriter::reopen(fs::path folder, double t_restart,
                                    const nlohmann::json& metadata) {
  if (!std::isfinite(t_restart)) {
    throw std::invalid_argument(fmt::format("restart time {} is not finite", t_restart));
  }
  auto s = std::make_unique<State>();
  s->folder = std::move(folder);
  const fs::path path = s->h5_path();
  RunFileSurvey survey;
  {
    const h5::File f = h5::File::open(path, h5::File::Mode::read_only, true);
    survey = survey_run_file(f, path.string(), t_restart);
  }
  // HDF5 keeps no journal: a run killed while it wrote run.h5 can leave an object whose header is
  // damaged, which can be neither read nor unlinked. Outputs are written before the checkpoint of
  // their time, so such an object lies after the restart time: the restart drops it with the rest,
  // in place when it can, else by copying what it keeps into a new run.h5.
  s->run_file_rebuilt = survey.damaged;
  if (!s->run_file_rebuilt) {
    try {
      h5::File f = h5::File::open(path, h5::File::Mode::read_write, true);
      for (const std::string& name : survey.dropped) f.remove(name);
      f.close();
    } catch (const IoError&) {
      s->run_file_rebuilt = true;
    }
  }
  if (s->run_file_rebuilt) rebuild_run_file(path, survey);
  if (!metadata.empty()) {
    h5::File f = h5::File::open(path, h5::File::Mode::read_write, true);
    {
      h5::Group restarts = f.require_group("metadata/restarts");
      h5::Group r = restarts.create_group(std::to_string(restarts.children().size()));
      write_metadata(r, metadata);
      r.set_attribute("t_restart", t_restart);
    }
    f.close();
  }
  s->num_triangles = survey.num_triangles;
  s->num_nodes = survey.num_nodes;
  s->parts = std::move(survey.parts);
  for (auto& [k, st] : survey.kept) {
    s->steps.push_back(std::move(st));
    s->next_index = k + 1;
  }
  ResultsWriter w(std::move(s));
  w.rewrite_xdmf();
  TimeseriesCsv::truncate_after(w.s_->folder / kTimeseriesCsv, t_restart);
  // Rows the CSV lost (cut by a crash) come back from run.h5 (a run.h5 of an older capsflow has
  // none: the CSV is then kept as it is).
  if (!survey.csv_header.empty()) {
    std::vector<std::string> lines;
    for (const auto& [k, line] : survey.csv_rows) lines.push_back(line);
    TimeseriesCsv::restore_rows(w.s_->folder / kTimeseriesCsv, survey.csv_header, lines);
  }
  return w;
}

void ResultsWriter::write_step(double t, const Points& positions, const NamedFields& nodal_fields) {
  State& s = *s_;
  if (!std::isfinite(t))
    throw std::invalid_argument(fmt::format("write_step: time {} is not finite", t));
  if (!s.steps.empty() && !(t > s.steps.back().time)) {
    throw std::invalid_argument(fmt::format(
        "write_step: time {} is not after the last output time {}", t, s.steps.back().time));
  }
  if (positions.rows() != s.num_nodes) {
    throw std::invalid_argument(
        fmt::format("write_step: positions have {} rows, the mesh has {} nodes", positions.rows(),
                    s.num_nodes));
  }
  std::set<std::string> seen;
  XdmfStep st{t, step_group(s.next_index), {}};
  for (const auto& [name, values] : nodal_fields) {
    if (name.empty() || name == "positions" || name == "." || name.find('/') != std::string::npos ||
        !seen.insert(name).second) {
      throw std::invalid_argument("write_step: bad or duplicate field name '" + name + "'");
    }
    const Eigen::Index c = values.cols();
    if (values.rows() != s.num_nodes || (c != 1 && c != 3 && c != 6 && c != 9)) {
      throw std::invalid_argument(
          fmt::format("write_step: field '{}' is {}x{}; expected {} rows and 1, 3, 6 or 9 columns",
                      name, values.rows(), c, s.num_nodes));
    }
    st.fields.push_back({name, int(c), false});
  }

  {
    h5::File f = h5::File::open(s.h5_path(), h5::File::Mode::read_write, true);
    if (f.exists(st.group)) f.remove(st.group);  // left over by an earlier failed attempt
    {
      h5::Group g = f.create_group(st.group);
      g.write_matrix("positions", positions);
      for (const auto& [name, values] : nodal_fields) {
        if (values.cols() == 1) {
          g.write_vector(name, values.col(0));
        } else {
          g.write_matrix(name, values);
        }
      }
      g.set_attribute("time", t);
    }
    f.close();  // all object handles are closed above, so the file is really closed here
  }
  s.steps.push_back(std::move(st));
  ++s.next_index;
  rewrite_xdmf();
}

void ResultsWriter::write_profiles(const std::vector<PlaneProfile>& planes) {
  const State& s = *s_;
  if (s.steps.empty()) throw std::logic_error("write_profiles: no step written yet");
  h5::File f = h5::File::open(s.h5_path(), h5::File::Mode::read_write, true);
  const std::string name = fmt::format("profiles/{:06}", s.steps.size() - 1);
  {
    h5::Group g = f.require_group(name);
    g.set_attribute("time", s.steps.back().time);
    for (const PlaneProfile& p : planes) {
      h5::Group pg = g.require_group(p.plane);
      pg.write_matrix("points", p.points);
      pg.write_vector("offsets", p.offsets);
    }
  }
  f.close();  // all object handles are closed above, so the file is really closed here
}

void ResultsWriter::append_row(const CsvRow& row) {
  if (!s_->csv) s_->csv.emplace(s_->folder / kTimeseriesCsv);
  // run.h5 keeps each row beside its step (attribute csv_row, the header as /steps' csv_header),
  // written before the CSV's: a restart restores the rows a crash cut from the CSV (reopen).
  if (!s_->steps.empty()) {
    // The header once, with the CSV's first row (a restarted CSV has it already, and so has run.h5).
    const std::string header = s_->csv->columns().empty() ? TimeseriesCsv::header_line(row) : std::string();
    h5::File f = h5::File::open(s_->h5_path(), h5::File::Mode::read_write, true);
    {
      if (!header.empty()) f.open_group("steps").set_attribute("csv_header", header);
      f.open_group(s_->steps.back().group).set_attribute("csv_row", TimeseriesCsv::value_line(row));
    }
    f.close();
  }
  s_->csv->append_row(row);
}

void ResultsWriter::write_summary(const nlohmann::json& summary) {
  write_file_atomically(s_->folder / kSummaryJson, dump_json(summary) + "\n");
}

void ResultsWriter::write_timings(const nlohmann::json& table) {
  h5::File f = h5::File::open(s_->h5_path(), h5::File::Mode::read_write, true);
  if (f.exists("timing")) f.remove("timing");
  {
    h5::Group g = f.create_group("timing");
    g.write_string("json", dump_json(table));
    flatten_numbers(g, table, "");
  }
  f.close();
}

void ResultsWriter::rewrite_xdmf() const {
  const fs::path path = s_->folder / kRunXdmf;
  if (s_->steps.empty()) {
    // ParaView 5.11's XDMF Reader crashes (SIGSEGV) on an empty temporal collection: until
    // there is a step, there is no run.xmf.
    std::error_code ec;
    fs::remove(path, ec);
    if (ec) throw IoError("cannot remove '" + path.string() + "': " + ec.message());
    return;
  }
  write_file_atomically(path,
                        render_xdmf(kRunH5, s_->num_nodes, s_->num_triangles, s_->steps, s_->parts));
}

const fs::path& ResultsWriter::folder() const { return s_->folder; }
bool ResultsWriter::run_file_rebuilt() const { return s_->run_file_rebuilt; }
std::size_t ResultsWriter::num_steps() const { return s_->steps.size(); }
double ResultsWriter::last_time() const {
  return s_->steps.empty() ? -std::numeric_limits<double>::infinity() : s_->steps.back().time;
}
Eigen::Index ResultsWriter::num_nodes() const { return s_->num_nodes; }
Eigen::Index ResultsWriter::num_triangles() const { return s_->num_triangles; }
const MeshParts& ResultsWriter::parts() const { return s_->parts; }

}  // namespace capsflow::io
