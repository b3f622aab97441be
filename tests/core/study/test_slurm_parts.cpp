// The parts of `--scheduler slurm` and `--jobs` that need no cluster: reading Slurm's answers,
// the site options, job sizes and their margins, the batch script, the --jobs order. The real
// cluster runs in tests/slurm/.
#include <gtest/gtest.h>

#include <cmath>

#include "capsflow/core/study/cost_model.hpp"
#include "capsflow/core/study/local_jobs.hpp"
#include "capsflow/core/study/slurm_client.hpp"
#include "capsflow/core/study/slurm_script.hpp"
#include "capsflow/core/study/slurm_sizing.hpp"
#include "capsflow/core/study/variant_command.hpp"

using namespace capsflow;
using namespace capsflow::study;

TEST(SlurmAnswers, JobIdsStatesAndErrorsAreRead) {
  EXPECT_EQ(parse_sbatch_job_id("12345\n"), "12345");
  EXPECT_EQ(parse_sbatch_job_id("12345;cluster2\n"), "12345");  // --parsable on a federation
  EXPECT_FALSE(parse_sbatch_job_id("Submitted batch job 12\n"));
  // squeue -h -r -o '%i|%T' as Slurm 22.05 prints it for an array with two tasks and a plain job.
  const auto q = parse_squeue("12_0|RUNNING\n12_3|PENDING\n14|COMPLETING\n15|COMPLETED\n");
  ASSERT_EQ(q.size(), 3u);  // a job shown as COMPLETED for a moment is not active
  EXPECT_EQ(q.at("12_0"), QueueState::Running);
  EXPECT_EQ(q.at("12_3"), QueueState::Queued);
  EXPECT_EQ(q.at("14"), QueueState::Running);
  EXPECT_EQ(parse_scontrol_job("JobId=7 ArrayJobId=6 ArrayTaskId=1 JobName=capsflow-variant UserId=root(0) JobState=FAILED "
                               "Reason=NonZeroExitCode Dependency=(null) ExitCode=1:0 RunTime=00:00:01"),
            "FAILED, exit 1:0");
  EXPECT_EQ(parse_scontrol_job("slurm_load_jobs error: Invalid job id specified"), "");
  EXPECT_EQ(first_error_line("sbatch: error: invalid partition specified: nowhere\nallocation failure: Invalid partition name\n"),
            "invalid partition specified: nowhere");
}

TEST(SlurmSiteOptions, OptionsCapsflowSetsAreRefusedOthersPass) {
  EXPECT_NO_THROW(check_site_options({"--partition=short", "--account=proj42", "--qos=normal", "--time=2:00:00", "-p short"}));  // one #SBATCH line each
  for (const char* bad : {"--array=1-3", "-a1", "--dependency=afterok:3", "--output=x.out", "-J", "--wrap=hostname", "--signal=USR1"})
    EXPECT_THROW(check_site_options({bad}), std::runtime_error) << bad;
  EXPECT_THROW(check_site_options({"partition=short"}), std::runtime_error);  // not an option
  EXPECT_TRUE(site_sets({"--time=2:00:00"}, "--time", "-t"));
  EXPECT_TRUE(site_sets({"-t120"}, "--time", "-t"));
  EXPECT_FALSE(site_sets({"--partition=short"}, "--time", "-t"));
}

TEST(SlurmSizing, TimeMemoryAndThreadsFollowTheCostModelWithTheStatedMargins) {
  const StudyPlan p = make_study_plan("", {"time.scheme=rkc", "time.t_end=5", "fluid.backend=direct"}, {3, 4, 5}, {});
  CostModel cost(1.5);
  // Nothing measured: the reference anchor, 14.3 s per unit of γ̇t at 5120 elements, × (N/5120)^1.5.
  const JobSize l4 = size_job(p.variants[1], cost, 0, 0);
  EXPECT_FALSE(l4.fitted);
  EXPECT_NEAR(l4.predicted_seconds, 14.3 * 5, 1e-9);
  EXPECT_EQ(l4.minutes, 10);  // 3 × 71.5 s < the 10 min floor
  EXPECT_EQ(l4.threads, 2);   // one thread per 2560 elements
  // Memory: the peak estimate × 2 + 200 MB, in 100 MB (info/memory_estimate.cpp): (3.6 kB × 5120 + 18 MB) × 2
  // + 200 MB = 273 MB → 300 MB with the direct far field at 5120 elements.
  EXPECT_EQ(l4.memory_mb, 300);
  // Measured: 600 s at L4 predicts 600 × 4^1.5 = 4800 s at L5 (one size measured: β stays 1.5); × 3 → 240 min.
  cost.add("", 5120, 600);
  const JobSize l5 = size_job(p.variants[2], cost, 0, 0);
  EXPECT_TRUE(l5.fitted);
  EXPECT_NEAR(l5.predicted_seconds, 4800, 1e-6);
  EXPECT_EQ(l5.minutes, 240);
  EXPECT_EQ(l5.threads, 8);
  EXPECT_EQ(l5.memory_mb, 400);  // (3.6 kB × 20 480 + 18 MB) × 2 + 200 MB = 383 MB, rounded up
  // With the FMM its fixed part counts, at p = 8 (fluid.tolerance "auto"): (4.37 kB × 1280 + 295 MB) × 2
  // + 200 MB = 801 MB → 900 MB; at p = 9 (1e-6): (4.95 kB × 1280 + 475 MB) × 2 + 200 MB = 1163 MB → 1200 MB.
  const StudyPlan fmm = make_study_plan("", {"fluid.backend=fmm"}, {3}, {});
  EXPECT_EQ(size_job(fmm.variants[0], cost, 0, 0).memory_mb, 900);
  const StudyPlan fmm9 = make_study_plan("", {"fluid.backend=fmm", "fluid.tolerance=1e-6"}, {3}, {});
  EXPECT_EQ(size_job(fmm9.variants[0], cost, 0, 0).memory_mb, 1200);
  // And at λ ≠ 1 (the single layer at p = 9) the double layer's: + (9.0 kB × 1280 + 2000 MB) × 2 = 5186 MB → 5200 MB.
  const StudyPlan lambda = make_study_plan("", {"fluid.backend=fmm", "fluid.viscosity_ratio=5"}, {3}, {});
  EXPECT_EQ(size_job(lambda.variants[0], cost, 0, 0).memory_mb, 5200);
  // A variant that ran out of time gets at least twice its last limit; --threads wins.
  EXPECT_EQ(size_job(p.variants[1], cost, 0, 45).minutes, 90);
  EXPECT_EQ(size_job(p.variants[2], cost, 3, 0).threads, 3);
}

TEST(SlurmScript, RunsEachTaskAsTheStudysOwnCommandForOneVariant) {
  StudyOptions o;
  o.scene_path = "/data/scene with space.toml";
  o.overrides = {"time.t_end=0.5"};
  o.levels = {1, 2};
  o.vary = {parse_vary("fluid.geometry=flat,curved")};
  o.dir = "/scratch/s";
  o.slurm_options = {"--partition=short"};
  const StudyPlan p = make_study_plan("", o.overrides, o.levels, o.vary);
  const std::string s = variants_script("/opt/capsflow", o, p, {{3, &p.variants[3], JobSize{1, 300, 10, 1, false}}});
  EXPECT_EQ(s.rfind("#!/bin/bash\n", 0), 0u);
  EXPECT_NE(s.find("#SBATCH --partition=short\n"), std::string::npos);
  EXPECT_NE(s.find("#SBATCH --signal=B:TERM@120\n"), std::string::npos);
  EXPECT_NE(s.find("#SBATCH --output=/scratch/s/slurm/variant-%A_%a.out\n"), std::string::npos);
  EXPECT_NE(s.find("variants=(geometry=flat_L1 geometry=curved_L1 geometry=flat_L2 geometry=curved_L2)"), std::string::npos);
  EXPECT_NE(s.find("exec /opt/capsflow study '/data/scene with space.toml' --levels 1,2 --set time.t_end=0.5 "
                   "--vary fluid.geometry=flat,curved -o /scratch/s --variant \"${variants[$SLURM_ARRAY_TASK_ID]}\""),
            std::string::npos)
      << s;
  // Every #SBATCH line comes before the first command (sbatch stops reading them there).
  EXPECT_LT(s.rfind("#SBATCH"), s.find("\nset -u"));
  EXPECT_EQ(shell_quote("it's"), "'it'\\''s'");
}

TEST(LocalJobs, TheLongestPredictedVariantsStartFirst) {
  const StudyPlan p = make_study_plan("", {}, {1, 2, 3}, {parse_vary("fluid.geometry=flat,curved")});
  std::vector<VariantRecord> records(p.variants.size());
  std::vector<std::size_t> order = local_job_order(p, records);
  // Nothing measured: by N^β, finest first; equal sizes in plan order.
  EXPECT_EQ(order, (std::vector<std::size_t>{4, 5, 2, 3, 0, 1}));
  // Measured curved variants are 3× slower: curved L3 first; finished ones are not run.
  records[0].state = records[1].state = VariantState::Finished;
  for (int i : {0, 1}) {
    records[i].result = VariantResult{};
    records[i].result->elements = p.variants[i].elements;
    records[i].result->wall_seconds = i == 1 ? 3.0 : 1.0;
  }
  order = local_job_order(p, records);
  EXPECT_EQ(order, (std::vector<std::size_t>{5, 4, 3, 2}));
}
