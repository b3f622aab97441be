#pragma once
// `capsflow study --jobs K` (docs/study.md): K variants at once on this machine, each in a child
// process running the study's own command with --variant (variant_command.hpp), with the threads
// divided: --threads T (default: all cores) gives each child max(1, T / K).
//
// Order: the longest predicted first (the study's cost model, c·N^β: fitted to finished variants,
// else β alone, so the finest level first). The finest level dominates a study's cost — 4^β per
// level, 8–16× — so starting it first makes the study last about as long as its finest variant
// instead of the finest plus everything before it; among equal predictions, plan order.
//
// Each variant is the same run as in a sequential study (capsflow's results do not depend on the
// thread count), and the study files are written from the folders in plan order, so they are
// identical to a sequential study's apart from wall times.
//
// SIGINT/SIGTERM: no further variant starts; the signal is passed on to the running children
// (unless it came from the terminal, which signalled them itself), which stop with a checkpoint
// (exit 130); once they have ended, their states are read from their folders (interrupted, or
// pending without a checkpoint), study.json is written and the study exits 130. A second signal
// stops the children at once (SIGKILL): their last checkpoints, written atomically, stay.
#include <vector>

#include "capsflow/core/study/study_runner.hpp"
#include "capsflow/core/study/variant_record.hpp"

namespace capsflow::study {

// The order in which the open variants (not finished, not failed) start.
std::vector<std::size_t> local_job_order(const StudyPlan& plan, const std::vector<VariantRecord>& records);

// Runs the open variants and updates `records` from their folders. Returns 130 when interrupted,
// else 0; throws (one line) when a child ended without a result (after the others finished).
int run_local_jobs(const StudyPlan& plan, const StudyOptions& o, std::vector<VariantRecord>& records);

}  // namespace capsflow::study
