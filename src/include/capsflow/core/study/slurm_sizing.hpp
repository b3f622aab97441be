#pragma once
// What a variant's Slurm job asks for (docs/study.md §Sizing): threads, memory and time limit from
// the study's cost model (cost_model.hpp) and the scene, with margins:
//
// - time: the predicted wall time × 3, at least 10 minutes, in whole minutes. The prediction is
//   c·N^β fitted to the study's finished variants; until one has finished, the reference anchor
//   below scaled by t_end and (N/5120)^β. ×3 covers the fit extrapolating one level past its data
//   (β measured within ±0.3: 4^0.3 ≈ 1.5 per level) on a node that may be shared (×2). A variant
//   that ran out of time (or was stopped) before gets at least twice its previous limit, and
//   continues from its checkpoint.
// - threads: --threads when given, else one per 2560 elements rounded up to a power of two, 1 to
//   16: below a few thousand elements per thread the rotation and mass solves' OpenMP barriers
//   cost more than the threads bring (app/main.cpp). Not measured beyond 2 cores.
// - memory: the peak that `capsflow info` estimates (info/memory_estimate.hpp: by back end, the
//   double layer's included) × 2 + 200 MB, rounded up to 100 MB.
#include "capsflow/core/study/cost_model.hpp"
#include "capsflow/core/study/study_plan.hpp"

namespace capsflow::study {

// The reference anchor: the paper's Fig. 4 case with RKC at 5120 elements, 945 evaluations of
// 75.6 ms to γ̇t = 5 on 2 threads (README, study example): 14.3 s per unit of γ̇t.
inline constexpr double kReferenceSecondsPerUnitTime = 14.3;
inline constexpr long kReferenceElements = 5120;
inline constexpr double kTimeMargin = 3.0;
inline constexpr long kMinMinutes = 10;

struct JobSize {
  int threads = 1;
  long memory_mb = 0;
  long minutes = 0;
  double predicted_seconds = 0;
  bool fitted = false;  // the prediction comes from this study's own measurements
  bool operator==(const JobSize& o) const { return threads == o.threads && memory_mb == o.memory_mb && minutes == o.minutes; }
};

// `threads` is --threads (0: sized here); `previous_minutes` the limit of its last job (0: none).
JobSize size_job(const Variant& v, const CostModel& cost, int threads, long previous_minutes);

}  // namespace capsflow::study
