#include "capsflow/core/study/slurm_sizing.hpp"

#include <algorithm>
#include <cmath>

#include "capsflow/core/info/memory_estimate.hpp"
#include "capsflow/core/mesh/generation.hpp"

namespace capsflow::study {

JobSize size_job(const Variant& v, const CostModel& cost, int threads, long previous_minutes) {
  JobSize s;
  const double n = static_cast<double>(v.elements);
  if (threads > 0) {
    s.threads = threads;
  } else {
    s.threads = 1;
    while (s.threads < 16 && s.threads * 2560.0 < n) s.threads *= 2;
  }
  const double measured = cost.predict(v.family, v.elements);
  s.fitted = measured > 0;
  s.predicted_seconds = s.fitted ? measured
                                 : kReferenceSecondsPerUnitTime * v.scene.time.t_end *
                                       std::pow(n / static_cast<double>(kReferenceElements), cost.exponent());
  s.minutes = std::max(kMinMinutes, static_cast<long>(std::ceil(kTimeMargin * s.predicted_seconds / 60.0 - 1e-9)));
  s.minutes = std::max(s.minutes, 2 * previous_minutes);
  const double peak_mb = estimate_peak_memory(v.scene, expected_counts(v.scene.mesh.base, v.level)).total_mb();
  s.memory_mb = static_cast<long>(std::ceil((2 * peak_mb + 200) / 100.0)) * 100;
  return s;
}

}  // namespace capsflow::study
