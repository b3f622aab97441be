#pragma once
// The run's output, called by the time integrator (docs/scene-and-output.md §3):
//
//   DIR/run.h5          /mesh/triangles (int32 M×3), /mesh/reference_positions (float64 N×3),
//                       with several capsules also /mesh/parts/{node_offsets, element_offsets}
//                       (int64 K+1) and /mesh/parts/local_triangles (int32 M×3, each capsule's
//                       triangles numbering its own nodes from 0: see MeshParts below),
//                       /metadata, /steps/<k>/{positions, <fields>} with attribute `time`
//                       (and `csv_row`, the step's timeseries.csv line; /steps has the header
//                       as `csv_header`: a restart restores CSV rows a crash cut),
//                       /profiles/<k>/<plane>/{points, offsets} with attribute `time` (the
//                       cross-sections of output k: write_profiles), /timing (written at the end)
//   DIR/run.xmf         XDMF index for ParaView, rewritten atomically after every step; absent
//                       while there is no step (ParaView's XDMF Reader crashes on an empty one).
//                       ParaView users: open run.xmf with the "XDMF Reader" (see xdmf.hpp).
//   DIR/timeseries.csv  one row of scalars per append_row (see timeseries_csv.hpp)
//   DIR/summary.json    written atomically by write_summary
//
// run.h5 is opened and closed around every write, never held open between steps: with HDF5
// >= 1.10 file locking a reader (ParaView, h5py) could otherwise not open it during the run, and
// a crash leaves a file whose completed steps are all readable.
//
// Several capsules are written as one union mesh (MeshParts, declared in xdmf.hpp): capsule k's
// nodes and triangles are consecutive row ranges of the union, whose triangles hold global node
// indices, and every nodal field has the union's N rows. /mesh/parts records the ranges, and
// run.xmf shows each capsule as its own grid. One surface (no parts, or one) has no /mesh/parts.
//
// Step groups are named with six zero-padded digits (/steps/000000, /steps/000001, ...) so that
// sorted names are time order in h5py and h5ls. Nodal fields with 1 column are stored 1-D [N],
// others [N, c] with c = 3 (Vector), 6 (Tensor6) or 9 (Tensor). Times must increase strictly.
//
// Not thread-safe; call from one thread (rank 0 later).
#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "capsflow/core/io/timeseries_csv.hpp"
#include "capsflow/core/io/xdmf.hpp"
#include "capsflow/core/types.hpp"
#include "capsflow/core/io/io_error.hpp"

namespace capsflow::io {

inline constexpr const char* kRunH5 = "run.h5";
inline constexpr const char* kRunXdmf = "run.xmf";
inline constexpr const char* kTimeseriesCsv = "timeseries.csv";
inline constexpr const char* kSummaryJson = "summary.json";
// Version of the layout above; bump when a reader would need to change.
inline constexpr std::int64_t kOutputSchemaVersion = 1;

// A named nodal field: N rows, 1/3/6/9 columns. Points and Eigen::VectorXd convert implicitly.
using NamedField = std::pair<std::string, Eigen::MatrixXd>;
using NamedFields = std::vector<NamedField>;

// The cross-section of the surface in one plane: polylines as points and offsets (write_profiles).
struct PlaneProfile {
  std::string plane;  // the group name, e.g. "x1x2"
  Points points;
  Eigen::VectorXi offsets;
};

class ResultsWriter {
 public:
  // New run in a prepared folder (see output_folder.hpp). Creates run.h5 with the mesh and the
  // metadata. Metadata is a JSON object; each key becomes an entry of /metadata:
  //   string → string dataset; integer / bool → int64 attribute; float → float64 attribute;
  //   object / array → string dataset holding the JSON text.
  // Suggested keys: "scene_toml" (verbatim input), "scene_resolved" (object), "command_line",
  // "version", "git_hash", "library_versions" (object), "threads", "build".
  // The writer adds attributes schema_version, hdf5_version, created_utc and hostname itself.
  // An existing timeseries.csv or summary.json in `folder` (an earlier run) is removed.
  // `parts` splits `reference_mesh` (the union) into capsules; with more than one, run.h5 gets
  // /mesh/parts. Throws std::invalid_argument, before touching the folder, unless the offsets
  // start at 0, increase strictly and end at the mesh's counts and every triangle of a capsule
  // uses only that capsule's nodes.
  ResultsWriter(std::filesystem::path folder, const SurfaceMesh& reference_mesh,
                const nlohmann::json& metadata, MeshParts parts = {});

  // Restart: open an existing run folder, drop the steps with time > t_restart from run.h5 and
  // run.xmf and the CSV rows with t > t_restart (a step at exactly t_restart is kept: do not
  // write it again), their profiles, and the CSV rows with t > t_restart; CSV rows that run.h5
  // keeps but the CSV lost are written back. Non-empty `metadata` (the restarted run's command
  // line, ...) is recorded under /metadata/restarts/<n> with attribute t_restart. A run.h5 with a
  // damaged object after the restart time (a run killed while writing it) is rebuilt from what the
  // restart keeps (run_file_rebuilt()); a damaged one before it is an IoError naming it.
  // The capsules come back from /mesh/parts (parts()), so run.xmf keeps one grid per capsule.
  static ResultsWriter reopen(std::filesystem::path folder, double t_restart,
                              const nlohmann::json& metadata = nlohmann::json::object());

  ResultsWriter(ResultsWriter&&) noexcept;
  ResultsWriter& operator=(ResultsWriter&&) noexcept;
  ~ResultsWriter();

  // Append /steps/<k> (positions N×3, fields, attribute time), close run.h5, rewrite run.xmf.
  // Throws std::invalid_argument for wrong shapes, duplicate or reserved names, or t not
  // greater than the last step's time; IoError for I/O failures.
  void write_step(double t, const Points& positions, const NamedFields& nodal_fields = {});

  // Cross-sections of the last written step as /profiles/<k> (k: its position among the steps,
  // six digits), one group per plane: `points` (M×3, the polylines one after another) and
  // `offsets` (int32, lines + 1: line i is points[offsets[i], offsets[i+1])). Kept beside /steps,
  // whose groups hold nodal fields only. Replaces a group left by a run continued by --restart.
  void write_profiles(const std::vector<PlaneProfile>& planes);

  // One row of timeseries.csv (header from the first row; see timeseries_csv.hpp), also kept in
  // run.h5 beside the last written step.
  void append_row(const CsvRow& row);

  // summary.json, written atomically (keys: docs/scene-and-output.md §3.5).
  void write_summary(const nlohmann::json& summary);

  // Timer table into run.h5:/timing, replacing an earlier one: the JSON text as /timing/json,
  // plus every numeric leaf as a float64 attribute of /timing named by its dotted key path
  // (e.g. {"step": {"fluid": 1.5}} → attribute "step.fluid" = 1.5).
  void write_timings(const nlohmann::json& table);

  const std::filesystem::path& folder() const;
  // reopen found a damaged object in run.h5 and wrote a new run.h5 without it.
  bool run_file_rebuilt() const;
  std::size_t num_steps() const;
  double last_time() const;  // time of the last step; -inf when there is none
  Eigen::Index num_nodes() const;
  Eigen::Index num_triangles() const;
  // The capsules: K + 1 node and element offsets, K >= 1 (one part spanning the whole mesh for a
  // run of one surface, whether the constructor was given no parts or one).
  const MeshParts& parts() const;

 private:
  struct State;
  explicit ResultsWriter(std::unique_ptr<State> s);
  void rewrite_xdmf() const;
  std::unique_ptr<State> s_;
};

}  // namespace capsflow::io
