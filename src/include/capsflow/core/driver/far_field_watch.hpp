#pragma once
// fluid.verify_every over a run (docs/scene-and-output.md §2.6): the boundary integral's operators
// re-sum their far field directly every N evaluations and keep the latest, the worst and the count
// above the tolerance (bie/far_field.hpp, FarFieldCheckLog). This adds the run's side for one
// operator — the single layer, and with fluid.viscosity_ratio ≠ 1 a second watch for the double
// layer: the latest check for the timeseries.csv rows, the worst over the whole run (restarted
// segments included, through the checkpoint) and the time it happened for summary.json, and one
// warning line the first time a check exceeds the requested far-field tolerance. Disabled
// (verify_every = 0, or no double layer) it does nothing and adds no column or key.
#include <nlohmann/json.hpp>
#include <string>

#include "capsflow/core/bie/far_field.hpp"
#include "capsflow/core/io/timeseries_csv.hpp"

namespace capsflow {

class FarFieldWatch {
 public:
  // name: the summary.json / checkpoint key and the prefix of the two CSV columns (name_max,
  // name_rms); label: how the warning names the check; scale: what the differences are relative to.
  FarFieldWatch(int every, double tolerance, std::string name = "far_field_check", std::string label = "far-field check",
                std::string scale = "max |v|")
      : every_(every), tolerance_(tolerance), name_(std::move(name)), label_(std::move(label)), scale_(std::move(scale)) {}
  bool enabled() const { return every_ > 0; }
  const std::string& name() const { return name_; }

  // Takes in the checks an operator (SingleLayer or DoubleLayer) made since the last call; t is
  // the time of the state being advanced (the time given to a new worst check, and printed in the
  // warning).
  template <class Operator>
  void update(const Operator& op, double t) { update(op.far_field_checks(), to_string(op.backend()), op.fmm_order(), t); }
  // timeseries.csv: name_max, name_rms of the latest check.
  void append_columns(io::CsvRow& row) const;
  // summary.json [name]: every, checks, tolerance, worst max/RMS, when, how often above, back end, order.
  template <class Operator>
  nlohmann::json summary(const Operator& op) const {
    nlohmann::json s = state(op.far_field_checks());
    s.update({{"every", every_}, {"tolerance", tolerance_}, {"backend", to_string(op.backend())}, {"fmm_order", op.fmm_order()}});
    return s;
  }
  // What a checkpoint carries so that the worst value and the counts span restarts.
  template <class Operator>
  nlohmann::json state(const Operator& op) const { return state(op.far_field_checks()); }
  void set_state(const nlohmann::json& s);

 private:
  void update(const FarFieldCheckLog& log, const char* backend, int fmm_order, double t);
  nlohmann::json state(const FarFieldCheckLog& log) const;

  int every_;
  double tolerance_;
  std::string name_, label_, scale_;
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
