// `capsflow study --scheduler slurm` when sbatch refuses, without a cluster: a stand-in sbatch
// and squeue first on PATH (shell scripts) refuse where the test says — the check with
// `--test-only`, or the real submission after the check passed (a limit reached in between).
// Either way the study files tell the truth afterwards: nothing shown as queued that was not
// submitted, and a refused --overwrite leaves the study as it was.
#include <gtest/gtest.h>
#include <sys/stat.h>

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

// Writes bin/sbatch, which refuses `--test-only` when `refuse_check`, else refuses the submission
// itself, with Slurm's own wording; and bin/squeue, an empty queue. PATH starts with bin/ while
// this object lives.
class FakeSlurm {
 public:
  FakeSlurm(const fs::path& dir, bool refuse_check) : saved_(std::getenv("PATH")) {
    fs::create_directories(dir / "bin");
    const std::string check = refuse_check ? "echo 'sbatch: error: invalid partition specified: nowhere' >&2; exit 1"
                                           : "echo 'sbatch: Job 7 to start at 2026-12-01T12:00:00' >&2; exit 0";
    script(dir / "bin" / "sbatch", "case \" $* \" in *' --test-only '*) " + check + ";; esac\n"
                                   "echo 'sbatch: error: Batch job submission failed: Job violates accounting/QOS policy' >&2\n"
                                   "exit 1\n");
    script(dir / "bin" / "squeue", "exit 0\n");
    setenv("PATH", ((dir / "bin").string() + ":" + saved_).c_str(), 1);
  }
  ~FakeSlurm() { setenv("PATH", saved_.c_str(), 1); }

 private:
  static void script(const fs::path& p, const std::string& body) {
    std::ofstream(p) << "#!/bin/sh\n" << body;
    fs::permissions(p, fs::perms::owner_all);
  }
  std::string saved_;
};

const std::string kTiny = "study --levels 1 --vary fluid.geometry=flat,curved --set wall.model=membrane --set wall.law=nh "
                          "--set flow.ca_s=0.2 --set time.t_end=0.02 --threads 2";

}  // namespace

TEST(StudySbatchRefusals, ASubmissionRefusedAfterItsCheckLeavesNoVariantShownAsQueued) {
  const capsflow_test::TempDir d("sbatch-refusals");
  const fs::path out = d.path / "s";
  const FakeSlurm slurm(d.path, false);
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

TEST(StudySbatchRefusals, ARefusedOverwriteLeavesTheStudyAsItWas) {
  const capsflow_test::TempDir d("sbatch-refusals");
  const fs::path out = d.path / "s";
  ASSERT_EQ(capsflow(kTiny + " -o " + out.string(), d.path).code, 0);  // a finished local study
  const std::string study_json = slurp(out / "study.json"), study_md = slurp(out / "study.md");
  const FakeSlurm slurm(d.path, true);
  const Result r = capsflow(kTiny + " --scheduler slurm --overwrite -o " + out.string(), d.path);
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("sbatch refused the study's jobs: invalid partition specified: nowhere"), std::string::npos) << r.out;
  EXPECT_EQ(slurp(out / "study.json"), study_json);
  EXPECT_EQ(slurp(out / "study.md"), study_md);
}
