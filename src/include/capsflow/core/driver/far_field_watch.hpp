#pragma once
// fluid.verify_every over a run (docs/scene-and-output.md §2.6): the boundary integral re-sums
// its far field directly every N evaluations and keeps the latest, the worst and the count above
// the tolerance (bie/single_layer.hpp, FarFieldCheck). This adds the run's side: the latest check
// for the timeseries.csv rows, the worst over the whole run (restarted segments included,
// through the checkpoint) and the time it happened for summary.json, and one warning line the
// first time a check exceeds the requested far-field tolerance. With verify_every = 0 it does
// nothing and adds no column or key.
#include <nlohmann/json.hpp>

#include "capsflow/core/bie/single_layer.hpp"
#include "capsflow/core/io/timeseries_csv.hpp"

namespace capsflow {

class FarFieldWatch {
 public:
  FarFieldWatch(int every, double tolerance) : every_(every), tolerance_(tolerance) {}
  bool enabled() const { return every_ > 0; }

  // Takes in the checks made since the last call; t is the time of the state being advanced (the
  // time given to a new worst check, and printed in the warning).
  void update(const SingleLayer& bie, double t);
  // timeseries.csv: far_field_check_max, far_field_check_rms of the latest check.
  void append_columns(io::CsvRow& row) const;
  // summary.json "far_field_check": every, checks, tolerance, worst max/RMS, when, how often above.
  nlohmann::json summary(const SingleLayer& bie) const;
  // What a checkpoint carries so that the worst value and the counts span restarts.
  nlohmann::json state(const SingleLayer& bie) const;
  void set_state(const nlohmann::json& s);

 private:
  int every_;
  double tolerance_;
  long seen_ = 0;  // checks of this segment taken in
  FarFieldCheck latest_;
  long worst_evaluation_ = -1;  // of this segment's worst check, to notice a new one
  double t_worst_ = 0;          // of this segment's worst check
  bool warned_ = false;
  // Earlier segments (restarts).
  long checks_before_ = 0, above_before_ = 0;
  double worst_max_before_ = 0, worst_rms_before_ = 0, t_worst_before_ = 0;
};

}  // namespace capsflow
