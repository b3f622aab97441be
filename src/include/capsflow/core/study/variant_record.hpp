#pragma once
// The study's view of one variant (same index as StudyPlan::variants): where it stands, typed,
// and its results once it has a summary. The states are study.json's `state` names
// (docs/scene-and-output.md §4.3); the scheduler adds queued and running (docs/study.md).
#include <optional>
#include <string>

#include "capsflow/core/named_enum.hpp"
#include "capsflow/core/study/variant_folder.hpp"

namespace capsflow::study {

enum class VariantState {
  Pending,      // not run yet (nothing usable in its folder)
  Queued,       // a scheduler job for it waits (Slurm)
  Running,      // it runs now (a Slurm job, or a --jobs child)
  Interrupted,  // stopped with a checkpoint: the next call continues from it
  Finished,     // stopped at t_end or at steady state
  Failed,       // a numerical stop (blow_up, solver_failure, no_progress, a stop_on condition)
  Error,        // ended without a result (an I/O error, a job killed before its first checkpoint): run again
};
inline constexpr NameTable<VariantState, 7> kVariantStateNames{{{VariantState::Pending, "pending"},
                                                                {VariantState::Queued, "queued"},
                                                                {VariantState::Running, "running"},
                                                                {VariantState::Interrupted, "interrupted"},
                                                                {VariantState::Finished, "finished"},
                                                                {VariantState::Failed, "failed"},
                                                                {VariantState::Error, "error"}}};
constexpr const auto& name_table(VariantState) { return kVariantStateNames; }

struct VariantRecord {
  VariantState state = VariantState::Pending;
  std::optional<VariantResult> result;  // finished and failed variants (both have a summary)
  std::string note;                     // why (an error's message), or the scheduler's job id
};

}  // namespace capsflow::study
