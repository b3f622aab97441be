// `capsflow study --scheduler slurm` against a real one-node Slurm (local_cluster.sh, started by
// the slurm_cluster ctest fixture): a small study submitted, waited for and compared with the
// same study run locally; a second call that skips what finished and resubmits a variant whose
// job failed; a variant whose solve failed (exit 3) marked failed and never submitted again; a
// variant stopped by SIGTERM before its time limit, resubmitted with more time,
// continuing from its checkpoint; a queued job neither submitted twice, nor run locally, nor
// overwritten; errors of the submission. Job states come from squeue/scontrol and the study's own
// files (the cluster has no accounting daemon).
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "run_capsflow.hpp"

namespace fs = std::filesystem;
using capsflow_test::capsflow;
using capsflow_test::Result;
using capsflow_test::json_of;
using capsflow_test::slurp;

namespace {

struct TempDir : capsflow_test::TempDir {
  TempDir() : capsflow_test::TempDir("slurm") {}
};

// The cluster of the fixture: SLURM_CONF set for this process and the capsflow it starts, or the
// reason it is not there (the test then skips).
std::string use_cluster() {
  const std::string state = slurp(CAPSFLOW_SLURM_STATE);
  if (state.empty()) return "no cluster state file " CAPSFLOW_SLURM_STATE " (run the slurm_cluster_start test first)";
  if (state.rfind("skip: ", 0) == 0) return state;
  const fs::path dir = state.substr(0, state.find('\n'));
  setenv("SLURM_CONF", (dir / "slurm.conf").c_str(), 1);
  return "";
}

int shell(const std::string& cmd) {
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// Waits until none of the study's recorded jobs is in the queue any more. Bounded: the jobs take
// a few seconds each; 240 s leaves room for a loaded machine (2 cores shared by the suite).
bool wait_for_jobs(const fs::path& study, double seconds = 240) {
  const nlohmann::json jobs = json_of(study / "slurm" / "jobs.json");
  std::string ids;
  for (const auto& s : jobs["submissions"]) ids += (ids.empty() ? "" : ",") + s["job"].get<std::string>();
  const auto start = std::chrono::steady_clock::now();
  while (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() < seconds) {
    if (shell("test -z \"$(squeue -h -j " + ids + " 2>/dev/null)\"") == 0) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
  }
  return false;
}

// A membrane capsule (no rotation solves) on levels 1–2 to γ̇t = 0.1: a second or two per variant.
const std::string kStudy = "study --levels 1,2 --vary fluid.geometry=flat,curved --set wall.model=membrane --set wall.law=nh "
                           "--set flow.ca_s=0.2 --set time.t_end=0.1 --set output.every=0.05 --threads 1";

// What must not depend on where the variants ran: states, stop reasons and final values of every
// variant, and every convergence row (study.csv holds no wall times, so it must be identical).
void expect_same_results(const fs::path& a, const fs::path& b) {
  EXPECT_EQ(slurp(a / "study.csv"), slurp(b / "study.csv"));  // bit for bit: the same runs, results independent of threads
  const nlohmann::json ja = json_of(a / "study.json"), jb = json_of(b / "study.json");
  ASSERT_EQ(ja["variants"].size(), jb["variants"].size());
  for (std::size_t i = 0; i < ja["variants"].size(); ++i) {
    const auto &va = ja["variants"][i], &vb = jb["variants"][i];
    EXPECT_EQ(va["name"], vb["name"]);
    EXPECT_EQ(va["state"], vb["state"]) << va["name"];
    EXPECT_EQ(va["final"], vb["final"]) << va["name"];
    EXPECT_EQ(va["rhs_evaluations"], vb["rhs_evaluations"]) << va["name"];
  }
  EXPECT_EQ(ja["final"], jb["final"]);
  EXPECT_EQ(ja["series"], jb["series"]);
}

// Each test runs on the fixture's cluster. Without one it skips, saying why — except under CI,
// where a skip would let CI pass without a study having run through Slurm.
class SlurmStudy : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string why = use_cluster();
    if (why.empty()) return;
    const char* ci = std::getenv("CI");
    if (ci && *ci) FAIL() << why << " (CI is set: the Slurm tests must run there)";
    GTEST_SKIP() << why;
  }
};

}  // namespace

TEST_F(SlurmStudy, RunsToItsAnalysisResubmitsAFailedVariantAndMatchesTheLocalStudy) {
  TempDir d;
  const fs::path local = d.path / "local", cluster = d.path / "cluster";
  const Result l = capsflow(kStudy + " -o " + local.string(), d.path);
  ASSERT_EQ(l.code, 0) << l.out;

  const Result first = capsflow(kStudy + " --scheduler slurm -o " + cluster.string(), d.path);
  ASSERT_EQ(first.code, 0) << first.out;
  EXPECT_NE(first.out.find("submitted 4 variants to Slurm"), std::string::npos) << first.out;
  EXPECT_NE(first.out.find("squeue -j"), std::string::npos) << first.out;
  EXPECT_TRUE(fs::exists(cluster / "slurm" / "variants.sh"));
  ASSERT_TRUE(wait_for_jobs(cluster)) << "the jobs did not leave the queue in time";
  // The analysis job wrote the study files: the same results as the local study.
  const nlohmann::json jobs = json_of(cluster / "slurm" / "jobs.json");
  const std::string analysis_log = slurp(cluster / jobs["analysis"]["log"].get<std::string>());
  EXPECT_NE(analysis_log.find("4 of 4 variants finished"), std::string::npos) << analysis_log;
  expect_same_results(local, cluster);

  // A variant whose job fails: its results gone and a folder named run.h5 in its way (the run
  // cannot replace it: an I/O error, exit 1). The next call submits it alone.
  const fs::path victim = cluster / "geometry=curved_L2";
  const std::string untouched = slurp(cluster / "geometry=flat_L2" / "summary.json");
  for (const char* f : {"summary.json", "run.h5", "checkpoint.h5", "checkpoint.prev.h5"}) fs::remove(victim / f);
  fs::create_directories(victim / "run.h5" / "blocker");
  const Result second = capsflow(kStudy + " --scheduler slurm -o " + cluster.string(), d.path);
  ASSERT_EQ(second.code, 0) << second.out;
  EXPECT_NE(second.out.find("submitted 1 variant to Slurm"), std::string::npos) << second.out;
  ASSERT_TRUE(wait_for_jobs(cluster));
  const nlohmann::json after_failure = json_of(cluster / "study.json");
  EXPECT_EQ(after_failure["variants"][3]["name"], "geometry=curved_L2");
  EXPECT_EQ(after_failure["variants"][3]["state"], "error");  // reported by the analysis job
  EXPECT_NE(after_failure["variants"][3]["note"].get<std::string>().find("capsflow: error:"), std::string::npos)
      << after_failure["variants"][3].dump();

  // The third call reports the failed job and submits it again; with the obstacle gone it finishes.
  fs::remove_all(victim / "run.h5");
  const Result third = capsflow(kStudy + " --scheduler slurm -o " + cluster.string(), d.path);
  ASSERT_EQ(third.code, 0) << third.out;
  EXPECT_NE(third.out.find("geometry=curved_L2: job "), std::string::npos) << third.out;
  EXPECT_NE(third.out.find("ended without a result"), std::string::npos) << third.out;
  EXPECT_NE(third.out.find("submitted 1 variant to Slurm"), std::string::npos) << third.out;
  ASSERT_TRUE(wait_for_jobs(cluster));
  EXPECT_EQ(slurp(cluster / "geometry=flat_L2" / "summary.json"), untouched);  // finished variants are never run again
  expect_same_results(local, cluster);

  // Everything finished: a fourth call submits nothing and analyses in place.
  const Result fourth = capsflow(kStudy + " --scheduler slurm -o " + cluster.string(), d.path);
  EXPECT_EQ(fourth.code, 0) << fourth.out;
  EXPECT_NE(fourth.out.find("every variant has a result: 4 of 4 finished"), std::string::npos) << fourth.out;
}

TEST_F(SlurmStudy, AQueuedVariantIsNeverSubmittedTwiceNorRunLocallyNorOverwritten) {
  TempDir d;
  const fs::path out = d.path / "s";
  const std::string local = "study --levels 1 --set wall.model=membrane --set time.t_end=0.02 --threads 1 -o " + out.string();
  const std::string tiny = local + " --scheduler slurm --slurm-opt=--hold";  // held: stays queued until released
  const Result first = capsflow(tiny, d.path);
  ASSERT_EQ(first.code, 0) << first.out;
  const Result second = capsflow(tiny, d.path);
  EXPECT_EQ(second.code, 0) << second.out;
  EXPECT_NE(second.out.find("nothing to submit: 0 finished, 1 queued"), std::string::npos) << second.out;
  const nlohmann::json jobs = json_of(out / "slurm" / "jobs.json");
  EXPECT_EQ(jobs["submissions"].size(), 2u);  // the variant's and the analysis, once
  const std::string job = jobs["variants"]["L1"]["job"].get<std::string>();

  // --analyse while the job waits: the variant is queued, not an error.
  const Result analysed = capsflow("study --analyse " + out.string(), d.path);
  EXPECT_EQ(analysed.code, 3) << analysed.out;  // not every variant finished
  EXPECT_NE(analysed.out.find("L1: queued (job " + job + ")"), std::string::npos) << analysed.out;
  EXPECT_EQ(json_of(out / "study.json")["variants"][0]["state"], "queued");
  // The same study run locally would write the folder the queued job will write: refused.
  const std::string study_json = slurp(out / "study.json");
  const Result here = capsflow(local, d.path);
  EXPECT_EQ(here.code, 1) << here.out;
  EXPECT_NE(here.out.find("jobs of this study are queued or running on Slurm (" + job + ")"), std::string::npos) << here.out;
  EXPECT_FALSE(fs::exists(out / "L1" / "summary.json"));
  // --overwrite is refused while the job waits, and leaves the study files as they were.
  const Result overwrite = capsflow(tiny + " --overwrite", d.path);
  EXPECT_EQ(overwrite.code, 1) << overwrite.out;
  EXPECT_NE(overwrite.out.find("--overwrite: jobs of this study are queued or running (" + job + ")"), std::string::npos)
      << overwrite.out;
  EXPECT_EQ(slurp(out / "study.json"), study_json);
  for (const auto& s : jobs["submissions"]) shell("scancel " + s["job"].get<std::string>());
  ASSERT_TRUE(wait_for_jobs(out, 60));
}

TEST_F(SlurmStudy, AVariantStoppedBeforeItsTimeLimitContinuesFromItsCheckpointWithMoreTime) {
  TempDir d;
  const fs::path out = d.path / "s", variant = out / "L3";
  // One variant of some seconds (level 3, 1280 elements, to γ̇t = 2, an output every 0.1).
  const std::string study = "study --levels 3 --set wall.model=membrane --set wall.law=nh --set flow.ca_s=0.2 "
                            "--set time.t_end=2 --set output.every=0.1 --threads 1 --scheduler slurm -o " + out.string();
  const Result first = capsflow(study, d.path);
  ASSERT_EQ(first.code, 0) << first.out;
  EXPECT_NE(slurp(out / "slurm" / "variants.sh").find("\n#SBATCH --signal=B:TERM@120\n"), std::string::npos);
  const nlohmann::json jobs = json_of(out / "slurm" / "jobs.json");
  const std::string job = jobs["variants"]["L3"]["job"].get<std::string>();
  const long minutes = jobs["variants"]["L3"]["minutes"].get<long>();

  // Once it has written its second output (t = 0.1 of 2): what that #SBATCH line makes Slurm do
  // two minutes before the time limit — SIGTERM to the batch shell, which is capsflow (exec).
  // Bounded: 240 s for the job to start and reach t = 0.1 on a loaded machine.
  bool started = false;
  for (int i = 0; i < 4800 && !started; ++i) {
    started = capsflow_test::series_rows(variant).size() >= 2;
    if (!started) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_TRUE(started) << "the variant did not reach its second output in time";
  ASSERT_EQ(shell("scancel --signal=TERM --batch " + job), 0);
  ASSERT_TRUE(wait_for_jobs(out)) << "the jobs did not leave the queue in time";
  const nlohmann::json stopped = json_of(variant / "summary.json");
  ASSERT_EQ(stopped["stop_reason"], "interrupted") << "the variant ended before the signal: make it longer";
  const double t_stop = stopped["t"].get<double>();
  EXPECT_GT(t_stop, 0.0);
  EXPECT_LT(t_stop, 2.0);
  EXPECT_EQ(json_of(out / "study.json")["variants"][0]["state"], "interrupted");  // written by the analysis job

  // The same command submits it again with twice the time limit, and it continues from its checkpoint.
  const Result second = capsflow(study, d.path);
  ASSERT_EQ(second.code, 0) << second.out;
  EXPECT_NE(second.out.find("L3: job " + job), std::string::npos) << second.out;
  EXPECT_NE(second.out.find("stopped with a checkpoint"), std::string::npos) << second.out;
  EXPECT_NE(second.out.find("submitted again with more time"), std::string::npos) << second.out;
  const nlohmann::json again = json_of(out / "slurm" / "jobs.json");
  EXPECT_EQ(again["variants"]["L3"]["minutes"].get<long>(), 2 * minutes);
  EXPECT_EQ(again["variants"]["L3"]["submissions"].get<int>(), 2);
  const nlohmann::json resubmission = again["submissions"][2];  // variants, analysis, then this one
  EXPECT_EQ(resubmission["kind"], "variants");
  EXPECT_NE(resubmission["sbatch"].dump().find("\"--time=" + std::to_string(2 * minutes) + "\""), std::string::npos)
      << resubmission.dump();
  ASSERT_TRUE(wait_for_jobs(out)) << "the jobs did not leave the queue in time";
  const nlohmann::json done = json_of(variant / "summary.json");
  EXPECT_EQ(done["stop_reason"], "t_end");
  EXPECT_DOUBLE_EQ(done["t"].get<double>(), 2.0);
  EXPECT_EQ(done["run_id"], stopped["run_id"]);  // the same run, continued
  // One continuous series: every output time 0, 0.1, …, 2 once, and the output the stop wrote at
  // t_stop (docs/scene-and-output.md §1.1) — unless t_stop is an output time itself.
  const auto rows = capsflow_test::series_rows(variant);
  std::size_t on_grid = 0, at_stop = 0;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const double t = rows[i].at("t");
    if (i > 0) {
      EXPECT_GT(t, rows[i - 1].at("t")) << i;  // no time twice, none back
    }
    if (std::abs(t - 0.1 * std::round(t / 0.1)) < 1e-9) {  // 1e-9: far above the CSV's round-trip precision, far below 0.1
      ++on_grid;
    } else if (std::abs(t - t_stop) < 1e-9) {
      ++at_stop;
    }
  }
  EXPECT_EQ(on_grid, 21u);
  EXPECT_EQ(on_grid + at_stop, rows.size());
  EXPECT_EQ(json_of(out / "study.json")["variants"][0]["state"], "finished");
}

// A variant whose solve fails (λ = 5 with GMRES capped at 3 iterations: solver_failure near
// γ̇t = 0.3, tests/app/test_health.cpp) exits 3 with its summary inside its Slurm job. The
// analysis job marks it failed, and the next call neither submits it again nor anything else: the
// same scene would fail the same way. Its sibling with GMRES uncapped finishes.
TEST_F(SlurmStudy, AVariantStoppedByASolverFailureIsMarkedFailedAndNeverSubmittedAgain) {
  TempDir d;
  const fs::path out = d.path / "s";
  const std::string study = "study " + std::string(CAPSFLOW_SOURCE_DIR) +
                            "/scenes/sphere_shear_lambda5.toml --levels 2 --vary fluid.max_gmres=3,100 "
                            "--set time.t_end=3 --threads 1 --scheduler slurm -o " + out.string();
  const Result first = capsflow(study, d.path);
  ASSERT_EQ(first.code, 0) << first.out;
  EXPECT_NE(first.out.find("submitted 2 variants to Slurm"), std::string::npos) << first.out;
  ASSERT_TRUE(wait_for_jobs(out)) << "the jobs did not leave the queue in time";
  const fs::path capped = out / "max_gmres=3_L2", uncapped = out / "max_gmres=100_L2";
  const nlohmann::json failed = json_of(capped / "summary.json");
  EXPECT_EQ(failed["stop_reason"].get<std::string>().rfind("solver_failure: viscosity-ratio GMRES", 0), 0u) << failed["stop_reason"];
  EXPECT_TRUE(fs::exists(capped / "checkpoint.h5"));  // the last healthy state, kept
  EXPECT_EQ(json_of(uncapped / "summary.json")["stop_reason"], "t_end");
  const nlohmann::json sj = json_of(out / "study.json");  // written by the analysis job
  for (const auto& v : sj["variants"])
    EXPECT_EQ(v["state"], v["name"] == "max_gmres=3_L2" ? "failed" : "finished") << v.dump();

  const std::string failed_text = slurp(capped / "summary.json");
  const nlohmann::json jobs_before = json_of(out / "slurm" / "jobs.json");
  const Result second = capsflow(study, d.path);
  EXPECT_EQ(second.code, 3) << second.out;  // as a local study's: a variant stopped numerically
  EXPECT_NE(second.out.find("max_gmres=3_L2: stopped earlier with solver_failure"), std::string::npos) << second.out;
  EXPECT_NE(second.out.find("not submitted again"), std::string::npos) << second.out;
  EXPECT_EQ(second.out.find("submitted 1 variant"), std::string::npos) << second.out;
  EXPECT_EQ(json_of(out / "slurm" / "jobs.json")["submissions"].size(), jobs_before["submissions"].size())
      << "a job was submitted";
  EXPECT_EQ(json_of(out / "slurm" / "jobs.json")["variants"]["max_gmres=3_L2"]["submissions"], 1);
  EXPECT_EQ(slurp(capped / "summary.json"), failed_text);  // never run again
}

TEST_F(SlurmStudy, RefusalsAreOneLineAndSubmitNothing) {
  TempDir d;
  const fs::path out = d.path / "s";
  const std::string tiny = "study --levels 1 --set wall.model=membrane --set time.t_end=0.02 --scheduler slurm -o " + out.string();
  // (site option, the message's key part)
  const std::pair<const char*, const char*> refusals[] = {
      {" --slurm-opt=--partition=nowhere", "sbatch refused the study's jobs: invalid partition specified: nowhere"},
      {" --slurm-opt=--array=1", "--slurm-opt --array=1: capsflow sets --array itself"},
      {" --slurm-opt=partition", "--slurm-opt 'partition': expected an sbatch option"},
  };
  for (const auto& [option, message] : refusals) {
    const Result r = capsflow(tiny + option, d.path);
    EXPECT_EQ(r.code, 1) << option << "\n" << r.out;
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;  // one line
    EXPECT_NE(r.out.find(message), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(out)) << option;  // nothing submitted, nothing written
  }
  // No sbatch on PATH: refused before the study folder exists.
  const Result no_path = [&] {
    const std::string saved = std::getenv("PATH");
    setenv("PATH", "/nonexistent", 1);
    const Result x = capsflow(tiny, d.path);
    setenv("PATH", saved.c_str(), 1);
    return x;
  }();
  EXPECT_EQ(no_path.code, 1) << no_path.out;
  EXPECT_NE(no_path.out.find("sbatch is not on PATH"), std::string::npos) << no_path.out;
  EXPECT_FALSE(fs::exists(out));
}
