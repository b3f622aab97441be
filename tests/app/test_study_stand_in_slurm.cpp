// `capsflow study --scheduler slurm` against stand-ins for sbatch, squeue and scontrol (shell
// scripts first on PATH), for what a real one-node cluster cannot show quickly (tests/slurm/):
// sbatch refusing the check (`--test-only`) or the submission after the check passed (a limit
// reached in between), and jobs killed at their time limit before their first checkpoint. The
// study files must tell the truth afterwards, and a variant that needs more time must get it.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "run_capsflow.hpp"

namespace fs = std::filesystem;
using capsflow_test::capsflow;
using capsflow_test::json_of;
using capsflow_test::Result;
using capsflow_test::slurp;

namespace {

// DIR/bin/{sbatch,squeue,scontrol} with the given bodies (sh), first on PATH while this object lives.
class StandInSlurm {
 public:
  StandInSlurm(const fs::path& dir, const std::string& sbatch, const std::string& scontrol = "exit 1\n")
      : saved_(std::getenv("PATH")) {
    fs::create_directories(dir / "bin");
    script(dir / "bin" / "sbatch", sbatch);
    script(dir / "bin" / "squeue", "exit 0\n");  // an empty queue: every job has ended
    script(dir / "bin" / "scontrol", scontrol);
    setenv("PATH", ((dir / "bin").string() + ":" + saved_).c_str(), 1);
  }
  ~StandInSlurm() { setenv("PATH", saved_.c_str(), 1); }

 private:
  static void script(const fs::path& p, const std::string& body) {
    std::ofstream(p) << "#!/bin/sh\n" << body;
    fs::permissions(p, fs::perms::owner_all);
  }
  std::string saved_;
};

// sbatch: `--test-only` answers `check` (a line of sh); a submission is refused with Slurm's wording.
std::string refusing_sbatch(const std::string& check) {
  return "case \" $* \" in *' --test-only '*) " + check + ";; esac\n"
         "echo 'sbatch: error: Batch job submission failed: Job violates accounting/QOS policy' >&2\nexit 1\n";
}
// sbatch: accepts everything; job ids 40, 41, … ; each submission's arguments appended to bin/sbatch.log.
const std::string kAcceptingSbatch = "case \" $* \" in *' --test-only '*) exit 0;; esac\n"
                                     "d=$(dirname \"$0\"); n=$(cat \"$d/next\" 2>/dev/null || echo 40); echo $((n + 1)) > \"$d/next\"\n"
                                     "echo \"$*\" >> \"$d/sbatch.log\"; echo \"$n\"\n";

const std::string kTiny = "study --levels 1 --vary fluid.geometry=flat,curved --set wall.model=membrane --set wall.law=nh "
                          "--set flow.ca_s=0.2 --set time.t_end=0.02 --threads 2";

}  // namespace

TEST(StudyStandInSlurm, ASubmissionRefusedAfterItsCheckLeavesNoVariantShownAsQueued) {
  const capsflow_test::TempDir d("stand-in-slurm");
  const fs::path out = d.path / "s";
  const StandInSlurm slurm(d.path, refusing_sbatch("exit 0"));
  const Result r = capsflow(kTiny + " --scheduler slurm -o " + out.string(), d.path);
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;  // one line
  EXPECT_NE(r.out.find("sbatch refused the submission: Batch job submission failed: Job violates accounting/QOS policy"),
            std::string::npos)
      << r.out;
  // The study files were written before the submission (the analysis job reads them): they must
  // not claim a job that Slurm refused.
  const nlohmann::json sj = json_of(out / "study.json");
  ASSERT_EQ(sj["variants"].size(), 2u);
  for (const auto& v : sj["variants"]) EXPECT_EQ(v["state"], "pending") << v.dump();
  EXPECT_TRUE(json_of(out / "slurm" / "jobs.json")["variants"].empty());
}

TEST(StudyStandInSlurm, ARefusedOverwriteLeavesTheStudyAsItWas) {
  const capsflow_test::TempDir d("stand-in-slurm");
  const fs::path out = d.path / "s";
  ASSERT_EQ(capsflow(kTiny + " -o " + out.string(), d.path).code, 0);  // a finished local study
  const std::string study_json = slurp(out / "study.json"), study_md = slurp(out / "study.md");
  const StandInSlurm slurm(d.path, refusing_sbatch("echo 'sbatch: error: invalid partition specified: nowhere' >&2; exit 1"));
  const Result r = capsflow(kTiny + " --scheduler slurm --overwrite -o " + out.string(), d.path);
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("sbatch refused the study's jobs: invalid partition specified: nowhere"), std::string::npos) << r.out;
  EXPECT_EQ(slurp(out / "study.json"), study_json);
  EXPECT_EQ(slurp(out / "study.md"), study_md);
}

TEST(StudyStandInSlurm, AJobKilledAtItsTimeLimitBeforeItsFirstCheckpointGetsTwiceTheTime) {
  const capsflow_test::TempDir d("stand-in-slurm");
  const fs::path out = d.path / "s";
  // Task 0 (flat): slurmctld still remembers it timed out. Task 1 (curved): forgotten (MinJobAge),
  // but its log ends with slurmstepd's line. Neither wrote anything to its folder.
  const StandInSlurm slurm(d.path, kAcceptingSbatch,
                           "case \"$*\" in *40_0*) echo 'JobId=42 ArrayJobId=40 ArrayTaskId=0 JobState=TIMEOUT Reason=TimeLimit "
                           "ExitCode=0:15';; *) exit 1;; esac\n");
  const Result first = capsflow(kTiny + " --scheduler slurm -o " + out.string(), d.path);
  ASSERT_EQ(first.code, 0) << first.out;
  const nlohmann::json jobs = json_of(out / "slurm" / "jobs.json");
  ASSERT_EQ(jobs["variants"]["geometry=curved_L1"]["job"], "40_1");
  const long minutes = jobs["variants"]["geometry=curved_L1"]["minutes"].get<long>();
  std::ofstream(out / "slurm" / "variant-40_1.out")
      << "slurmstepd: error: *** JOB 43 ON node1 CANCELLED AT 2026-12-01T12:10:00 DUE TO TIME LIMIT ***\n";

  const Result second = capsflow(kTiny + " --scheduler slurm -o " + out.string(), d.path);
  ASSERT_EQ(second.code, 0) << second.out;
  EXPECT_NE(second.out.find("geometry=flat_L1: job 40_0 (TIMEOUT, exit 0:15) ended without a result; submitted again with more time"),
            std::string::npos)
      << second.out;
  EXPECT_NE(second.out.find("DUE TO TIME LIMIT ***; submitted again with more time"), std::string::npos) << second.out;
  const nlohmann::json again = json_of(out / "slurm" / "jobs.json");
  for (const char* v : {"geometry=flat_L1", "geometry=curved_L1"}) {
    EXPECT_EQ(again["variants"][v]["minutes"].get<long>(), 2 * minutes) << v;
    EXPECT_EQ(again["variants"][v]["submissions"].get<int>(), 2) << v;
  }
  // The resubmission's sbatch line asks for it: variants 40, analysis 41, variants 42, analysis 43.
  EXPECT_NE(again["submissions"][2]["sbatch"].dump().find("\"--time=" + std::to_string(2 * minutes) + "\""), std::string::npos)
      << again["submissions"][2].dump();
}
