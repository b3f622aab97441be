// `capsflow study` end to end (docs/scene-and-output.md §4): a tiny study (levels 1–3, two
// families, a membrane capsule to γ̇t = 0.25), its files, resume after an interrupted variant,
// a variant that stopped numerically, and the one-line refusals.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "run_capsflow.hpp"

namespace fs = std::filesystem;

namespace {

using capsflow_test::capsflow;
using capsflow_test::Result;
struct TempDir : capsflow_test::TempDir {
  TempDir() : capsflow_test::TempDir("study") {}
};

using capsflow_test::json_of;
using capsflow_test::slurp;
int count_lines(const std::string& s) { return static_cast<int>(std::count(s.begin(), s.end(), '\n')); }

// A membrane capsule (no rotation solves: fast) on levels 1–3 (80 to 1280 elements), flat and
// curved; checkpoints every 0.1 so that a checkpoint before the end exists (t = 0.2).
const std::string kStudy =
    "study --levels 1,2,3 --vary fluid.geometry=flat,curved --set wall.model=membrane --set wall.law=nh "
    "--set flow.ca_s=0.2 --set time.t_end=0.25 --set output.every=0.05 --set output.checkpoint_every=0.1 --threads 2";

const char* kVariants[] = {"geometry=flat_L1", "geometry=curved_L1", "geometry=flat_L2",
                           "geometry=curved_L2", "geometry=flat_L3", "geometry=curved_L3"};

// The row of study.csv for (family, observable, time).
std::map<std::string, std::string> csv_row(const fs::path& csv, const std::string& family, const std::string& obs,
                                           const std::string& time) {
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> header;
  {
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) header.push_back(c);
  }
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
    if (cells.size() < 3 || cells[0] != family || cells[1] != obs || cells[2] != time) continue;
    std::map<std::string, std::string> row;
    for (std::size_t i = 0; i < header.size() && i < cells.size(); ++i) row[header[i]] = cells[i];
    return row;
  }
  return {};
}

}  // namespace

TEST(Study, TinyStudyRunsResumesAnInterruptedVariantAndReportsAFailedOne) {
  TempDir d;
  const fs::path out = d.path / "s";
  const Result first = capsflow(kStudy + " -o " + out.string(), d.path);
  ASSERT_EQ(first.code, 0) << first.out;
  // One progress line per variant, each with the ETA of the rest.
  for (const char* v : kVariants) {
    ASSERT_TRUE(fs::exists(out / v / "summary.json")) << v;
    EXPECT_EQ(json_of(out / v / "summary.json")["stop_reason"], "t_end") << v;
    EXPECT_NE(first.out.find(std::string("] ") + v + ": t_end at t = 0.25"), std::string::npos) << first.out;
  }
  EXPECT_NE(first.out.find("ETA"), std::string::npos) << first.out;
  for (const char* f : {"study.json", "study.csv", "study.md"}) EXPECT_TRUE(fs::exists(out / f)) << f;

  // study.json: every variant finished, with its cost; the final values are the variants' own.
  const nlohmann::json sj = json_of(out / "study.json");
  ASSERT_EQ(sj["variants"].size(), 6u);
  for (const auto& v : sj["variants"]) {
    EXPECT_EQ(v["state"], "finished") << v["name"];
    EXPECT_GT(v["rhs_evaluations"].get<long>(), 0) << v["name"];
    EXPECT_GT(v["peak_rss_mb"].get<double>(), 0.0) << v["name"];
    EXPECT_TRUE(v["seconds_per_evaluation_by_phase"].contains("bie_far")) << v["name"];
  }
  const auto curved_final_d13 = csv_row(out / "study.csv", "geometry=curved", "D13", "final");
  ASSERT_FALSE(curved_final_d13.empty());
  for (int l = 1; l <= 3; ++l) {
    const double from_run = json_of(out / ("geometry=curved_L" + std::to_string(l)) / "summary.json")["D13"].get<double>();
    EXPECT_EQ(std::stod(curved_final_d13.at("value_L" + std::to_string(l))), from_run);  // written in round-trip form
  }
  // At t = 0 every level is the discrete spheroid a/b = 1.4, whose D13 is exactly −1/6 on the
  // centrally symmetric meshes (docs/conventions.md §5.2): the study must see no change with the
  // level (round-off status) and extrapolate to −1/6.
  const auto d13_t0 = csv_row(out / "study.csv", "geometry=flat", "D13", "0");
  ASSERT_FALSE(d13_t0.empty());
  EXPECT_EQ(d13_t0.at("status"), "round_off");
  EXPECT_NEAR(std::stod(d13_t0.at("extrapolated")), -1.0 / 6, 1e-12);  // the exact value, to round-off of the moments
  EXPECT_EQ(d13_t0.at("order"), "");  // no order is claimed
  // Every status in the file is one of the documented ones, and only asymptotic rows carry an order.
  std::ifstream csv(out / "study.csv");
  std::string line;
  std::getline(csv, line);
  int rows = 0;
  while (std::getline(csv, line)) {
    std::vector<std::string> c;
    std::stringstream ss(line);
    for (std::string x; std::getline(ss, x, ',');) c.push_back(x);
    ASSERT_GE(c.size(), 5u) << line;
    EXPECT_TRUE(c[3] == "asymptotic" || c[3] == "non_monotone" || c[3] == "non_asymptotic" || c[3] == "round_off") << line;
    EXPECT_EQ(c[4].empty(), c[3] != "asymptotic") << line;
    EXPECT_EQ(line.find("nan"), std::string::npos) << line;
    ++rows;
  }
  // 2 families × 11 observables × (final + 6 output times t = 0, 0.05, ..., 0.25).
  EXPECT_EQ(rows, 2 * 11 * 7);
  EXPECT_NE(slurp(out / "study.md").find("## geometry=curved at the end"), std::string::npos);

  // Interrupt one variant: drop its summary and go back to its checkpoint at t = 0.2 (the run
  // was killed between the periodic checkpoint at 0.2 and the end).
  const fs::path interrupted = out / "geometry=curved_L2";
  const nlohmann::json before = json_of(interrupted / "summary.json");
  fs::remove(interrupted / "summary.json");
  fs::rename(interrupted / "checkpoint.prev.h5", interrupted / "checkpoint.h5");
  // And mark another one as stopped by a blow-up: it must be reported, not run again.
  const fs::path blown = out / "geometry=flat_L2";
  nlohmann::json b = json_of(blown / "summary.json");
  b["stop_reason"] = "blow_up";
  std::ofstream(blown / "summary.json") << b.dump(2);
  const std::string blown_text = slurp(blown / "summary.json");
  std::map<std::string, std::string> untouched;
  for (const char* v : {"geometry=flat_L1", "geometry=curved_L1", "geometry=flat_L3", "geometry=curved_L3"})
    untouched[v] = slurp(out / v / "summary.json");

  const Result second = capsflow(kStudy + " -o " + out.string(), d.path);
  EXPECT_EQ(second.code, 3) << second.out;  // one variant stopped numerically
  EXPECT_NE(second.out.find("geometry=curved_L2: continuing from its checkpoint"), std::string::npos) << second.out;
  EXPECT_NE(second.out.find("geometry=flat_L2: stopped earlier with blow_up; not run again"), std::string::npos) << second.out;
  EXPECT_NE(second.out.find("geometry=flat_L3: finished earlier"), std::string::npos) << second.out;
  for (const auto& [v, text] : untouched) EXPECT_EQ(slurp(out / v / "summary.json"), text) << v << " was run again";
  EXPECT_EQ(slurp(blown / "summary.json"), blown_text);
  // The resumed variant is the same run, continued: same id, and with the same thread count the
  // same state as the uninterrupted run (restart equivalence, tests/app/test_cli.cpp).
  const nlohmann::json after = json_of(interrupted / "summary.json");
  EXPECT_EQ(after["stop_reason"], "t_end");
  EXPECT_EQ(after["run_id"], before["run_id"]);
  EXPECT_NEAR(after["D13"].get<double>(), before["D13"].get<double>(), 1e-13);  // bit for bit in practice
  EXPECT_EQ(count_lines(slurp(interrupted / "timeseries.csv")), 1 + 6);  // one continuous series
  // The failed level is left out of its family's analysis, and the study says so.
  const nlohmann::json sj2 = json_of(out / "study.json");
  EXPECT_EQ(sj2["variants"][2]["state"], "failed");
  bool noted = false;
  for (const auto& n : sj2["notes"]) noted = noted || n.get<std::string>().find("L2 failed") != std::string::npos;
  EXPECT_TRUE(noted) << sj2["notes"].dump();
  const auto flat_final = csv_row(out / "study.csv", "geometry=flat", "D13", "final");
  EXPECT_EQ(flat_final.at("value_L2"), "");
  EXPECT_EQ(flat_final.at("value_L1"), "");  // not consecutive with L3: left out too
}

TEST(Study, BadInputIsAOneLineErrorNamingTheCulpritAndChangesNothing) {
  TempDir d;
  const fs::path out = d.path / "s";
  struct Case {
    std::string args, expect;
  } cases[] = {
      {"--levels 1,3", "--levels 1,3: levels must be consecutive"},
      {"--levels 2,x", "'x' is not an integer"},
      {"--levels 2,2,3", "level 2 is given twice"},
      {"--levels 1,2 --vary mesh.level=1,2", "--vary mesh.level: give the levels with --levels"},
      {"--levels 1,2 --vary fluid.geometry", "--vary fluid.geometry: expected section.key=value1,value2"},
      {"--levels 1,2 --vary fluid.geometry=flat,bent", "'bent' is not one of"},
      {"--levels 1,2 --vary fluid.geometryy=flat", "fluid.geometryy: unknown key"},
      {"--levels 1,2 --set fluid.verify_every=-2", "--set fluid.verify_every: -2 is out of range: must be in [0, 1000000]"},
      {"--levels 1,2 --set mesh.level=3", "--set mesh.level=3: a study sets mesh.level itself"},
  };
  for (const Case& c : cases) {
    const Result r = capsflow("study " + c.args + " -o " + out.string(), d.path);
    EXPECT_EQ(r.code, 1) << c.args << "\n" << r.out;
    EXPECT_EQ(count_lines(r.out), 1) << c.args << "\n" << r.out;
    EXPECT_NE(r.out.find(c.expect), std::string::npos) << c.args << "\n" << r.out;
    EXPECT_FALSE(fs::exists(out)) << c.args;  // refused before anything is created
  }
  // A non-empty folder that holds no study is refused and left as it was.
  fs::create_directories(out);
  std::ofstream(out / "notes.txt") << "mine";
  const Result r = capsflow("study --levels 1,2 -o " + out.string(), d.path);
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("holds no study.json"), std::string::npos) << r.out;
  EXPECT_EQ(std::distance(fs::directory_iterator(out), fs::directory_iterator()), 1);
}

TEST(Study, AVariantFolderOfAnotherSceneIsRefusedUnlessOverwrite) {
  TempDir d;
  const fs::path out = d.path / "s";
  const std::string tiny = "study --levels 1 --set wall.model=membrane --set wall.law=nh --set flow.ca_s=0.2 "
                           "--set time.t_end=0.02 --threads 2 -o " + out.string();
  ASSERT_EQ(capsflow(tiny, d.path).code, 0);
  const std::string summary = slurp(out / "L1" / "summary.json");
  // The study folder records the scene its variants share: another one is refused at once.
  const Result other = capsflow(tiny + " --set time.t_end=0.03", d.path);
  EXPECT_EQ(other.code, 1) << other.out;
  EXPECT_NE(other.out.find("is a study of another scene (time.t_end (0.02 there, 0.03 here))"), std::string::npos) << other.out;
  EXPECT_EQ(slurp(out / "L1" / "summary.json"), summary);
  // A key the studies vary is not part of what they share: varying it is no other scene.
  const Result varied = capsflow(tiny + " --vary time.t_end=0.02,0.03", d.path);
  EXPECT_EQ(varied.code, 0) << varied.out;
  // Without that record (a study.json of an older capsflow), the variant folder itself is checked.
  nlohmann::json sj = json_of(out / "study.json");
  sj["study"].erase("base_scene");
  std::ofstream(out / "study.json") << sj.dump(2);
  const Result variant = capsflow(tiny + " --set time.t_end=0.03", d.path);
  EXPECT_EQ(variant.code, 1) << variant.out;
  EXPECT_NE(variant.out.find("holds a run of another scene (time.t_end"), std::string::npos) << variant.out;
  EXPECT_EQ(slurp(out / "L1" / "summary.json"), summary);
  const Result again = capsflow(tiny + " --set time.t_end=0.03 --overwrite", d.path);
  EXPECT_EQ(again.code, 0) << again.out;
  EXPECT_DOUBLE_EQ(json_of(out / "L1" / "summary.json")["t"].get<double>(), 0.03);
  // --jobs runs each variant in a child: --overwrite must reach it, or the child finds the run of
  // another scene in its folder (or, for the same scene, keeps the old result).
  const Result jobs = capsflow(tiny + " --set time.t_end=0.04 --overwrite --jobs 2", d.path);
  EXPECT_EQ(jobs.code, 0) << jobs.out;
  EXPECT_DOUBLE_EQ(json_of(out / "L1" / "summary.json")["t"].get<double>(), 0.04);
}

TEST(Study, TheSceneMayFollowVaryAndSet) {
  // --vary and --set take one value per occurrence: the scene file after them is the scene.
  TempDir d;
  const fs::path scene = fs::path(CAPSFLOW_SOURCE_DIR) / "scenes" / "quick.toml";
  const Result r = capsflow("study --levels 1 --threads 2 -o " + (d.path / "s").string() +
                                " --set wall.model=membrane --set time.t_end=0.02 --vary fluid.geometry=flat " + scene.string(),
                            d.path);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_TRUE(fs::exists(d.path / "s" / "geometry=flat_L1" / "summary.json"));
  EXPECT_EQ(json_of(d.path / "s" / "study.json")["study"]["scene"], scene.string());
}

TEST(Study, AnalyseNeedsNeitherTheSceneFileNorTheFolderTheStudyStartedIn) {
  // A study started with a relative scene path, its folder moved and the scene file deleted:
  // --analyse from elsewhere still rebuilds the plan, from the scene text study.json recorded.
  TempDir d;
  const fs::path start = d.path / "start";
  fs::create_directories(start / "scenes");
  fs::copy_file(fs::path(CAPSFLOW_SOURCE_DIR) / "scenes" / "quick.toml", start / "scenes" / "q.toml");
  const Result r = capsflow("study scenes/q.toml --levels 1 --threads 2 -o s --set wall.model=membrane --set time.t_end=0.02",
                            d.path, start);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(json_of(start / "s" / "study.json")["study"]["scene"], "scenes/q.toml");  // as given: the report shows it
  fs::remove(start / "scenes" / "q.toml");
  fs::rename(start / "s", d.path / "moved");
  const Result an = capsflow("study --analyse moved", d.path, d.path);
  EXPECT_EQ(an.code, 0) << an.out;
  EXPECT_NE(an.out.find("1 of 1 variants finished"), std::string::npos) << an.out;
  // A study.json written before the text was recorded names the file it needs and where to run from.
  nlohmann::json old = json_of(d.path / "moved" / "study.json");
  old["study"].erase("scene_text");
  std::ofstream(d.path / "moved" / "study.json") << old.dump(1);
  const Result refused = capsflow("study --analyse moved", d.path, d.path);
  EXPECT_EQ(refused.code, 1) << refused.out;
  EXPECT_NE(refused.out.find("'scenes/q.toml', which is not found from here: run --analyse from the folder the study was started in"),
            std::string::npos)
      << refused.out;
}

TEST(Study, TwoJobsAtOnceGiveTheSequentialStudysResults) {
  // Levels 1–2 × two families, once one after the other with 2 threads, once two at a time with
  // one thread each (the finest first): the same runs, so the same study files apart from times.
  TempDir d;
  const std::string tiny = "study --levels 1,2 --vary fluid.geometry=flat,curved --set wall.model=membrane --set wall.law=nh "
                           "--set flow.ca_s=0.2 --set time.t_end=0.1 --set output.every=0.05 --threads 2 -o ";
  const Result seq = capsflow(tiny + (d.path / "seq").string(), d.path);
  ASSERT_EQ(seq.code, 0) << seq.out;
  const Result par = capsflow(tiny + (d.path / "par").string() + " --jobs 2", d.path);
  ASSERT_EQ(par.code, 0) << par.out;
  EXPECT_NE(par.out.find("2 at a time with 1 thread each, longest predicted first: geometry=flat_L2, geometry=curved_L2, "
                         "geometry=flat_L1, geometry=curved_L1"),
            std::string::npos)
      << par.out;
  // Bit for bit: capsflow's results do not depend on the thread count (docs/testing.md §2, thread-count invariance).
  EXPECT_EQ(slurp(d.path / "seq" / "study.csv"), slurp(d.path / "par" / "study.csv"));
  const nlohmann::json a = json_of(d.path / "seq" / "study.json"), b = json_of(d.path / "par" / "study.json");
  EXPECT_EQ(a["final"], b["final"]);
  EXPECT_EQ(a["series"], b["series"]);
  ASSERT_EQ(a["variants"].size(), b["variants"].size());
  for (std::size_t i = 0; i < a["variants"].size(); ++i) {
    EXPECT_EQ(a["variants"][i]["final"], b["variants"][i]["final"]) << i;
    EXPECT_EQ(a["variants"][i]["rhs_evaluations"], b["variants"][i]["rhs_evaluations"]) << i;
  }
  // --analyse reads the study back and says what is missing once a variant's results are gone.
  fs::remove(d.path / "par" / "geometry=curved_L2" / "summary.json");
  fs::remove(d.path / "par" / "geometry=curved_L2" / "checkpoint.h5");
  fs::remove(d.path / "par" / "geometry=curved_L2" / "checkpoint.prev.h5");
  const Result an = capsflow("study --analyse " + (d.path / "par").string(), d.path);
  EXPECT_EQ(an.code, 3) << an.out;  // not every variant has a result
  EXPECT_NE(an.out.find("3 of 4 variants finished"), std::string::npos) << an.out;
  EXPECT_NE(an.out.find("geometry=curved_L2: pending"), std::string::npos) << an.out;
  EXPECT_EQ(json_of(d.path / "par" / "study.json")["variants"][3]["state"], "pending");
  // Options that do not go together are one line, exit 1.
  const Result both = capsflow(tiny + (d.path / "x").string() + " --jobs 2 --scheduler slurm", d.path);
  EXPECT_EQ(both.code, 1) << both.out;
  EXPECT_NE(both.out.find("--jobs: only with --scheduler local"), std::string::npos) << both.out;
  EXPECT_FALSE(fs::exists(d.path / "x"));
}

TEST(Study, ASignalToAStudyWithJobsStopsItsRunningVariantsRecordsThemAndExits130) {
  // Three levels, two at a time, each variant tens of seconds long (γ̇t = 50): when the finest two
  // run, the coarsest is still waiting. SIGINT must start nothing more, let the two stop with their
  // checkpoints, record them in study.json and end the study with 130 — not wait for ever for the
  // variant it will not start.
  TempDir d;
  const fs::path out = d.path / "s";
  const pid_t pid = capsflow_test::spawn("study --levels 1,2,3 --set wall.model=membrane --set wall.law=nh --set flow.ca_s=0.2 "
                                         "--set time.t_end=50 --jobs 2 --threads 2 -o " + out.string(),
                                         d.path / "study.log");
  // Both children have written their first checkpoint: their set-up is over, the runs step.
  const bool started = capsflow_test::wait_until(
      [&] { return fs::exists(out / "L3" / "checkpoint.h5") && fs::exists(out / "L2" / "checkpoint.h5"); }, 120);
  if (!started) ::kill(pid, SIGKILL);
  ASSERT_TRUE(started) << slurp(d.path / "study.log");
  ::kill(pid, SIGINT);
  // The children stop within a step (well under a second at these levels); 60 s bounds a hang.
  ASSERT_EQ(capsflow_test::wait_or_kill(pid, 60), 130) << slurp(d.path / "study.log");
  const nlohmann::json sj = json_of(out / "study.json");
  std::map<std::string, std::string> state;
  for (const auto& v : sj["variants"]) state[v["name"].get<std::string>()] = v["state"].get<std::string>();
  EXPECT_EQ(state["L1"], "pending") << sj["variants"].dump();
  EXPECT_EQ(state["L2"], "interrupted") << sj["variants"].dump();
  EXPECT_EQ(state["L3"], "interrupted") << sj["variants"].dump();
  for (const char* v : {"L2", "L3"}) EXPECT_EQ(json_of(out / v / "summary.json")["stop_reason"], "interrupted") << v;
  EXPECT_FALSE(fs::exists(out / "L1")) << "a variant was started after the signal";
  EXPECT_FALSE(fs::exists(out / ".capsflow.lock")) << "the study released its folder";
}

TEST(Study, AStudyFileThatIsAFifoIsRefusedInsteadOfWaitingForAWriter) {
  // study.json or a variant's summary.json replaced by a FIFO: --analyse opened it and waited for
  // ever for a writer. timeout(1) bounds the old behaviour (exit 124).
  TempDir d;
  const fs::path out = d.path / "s";
  ASSERT_EQ(capsflow("study --levels 1 --set wall.model=membrane --set time.t_end=0.02 --threads 2 -o " + out.string(), d.path).code,
            0);
  const std::string analyse = std::string("timeout -k 5 30 ") + CAPSFLOW_EXE + " study --analyse " + out.string();
  const auto bounded = [&](const std::string& command) {
    const int status = std::system((command + " > " + (d.path / "bounded.txt").string() + " 2>&1").c_str());
    return Result{WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(d.path / "bounded.txt")};
  };
  for (const fs::path& file : {out / "L1" / "summary.json", out / "study.json"}) {
    fs::rename(file, d.path / "kept");
    ASSERT_EQ(::mkfifo(file.c_str(), 0600), 0);
    const Result r = bounded(analyse);
    EXPECT_EQ(r.code, 1) << file << "\n" << r.out;
    EXPECT_EQ(count_lines(r.out), 1) << r.out;
    EXPECT_NE(r.out.find("cannot read '" + file.string() + "': it is a FIFO, not a regular file"), std::string::npos) << r.out;
    fs::remove(file);
    fs::rename(d.path / "kept", file);
  }
  EXPECT_EQ(bounded(analyse).code, 0);  // the files back: the study reads as before
}

TEST(Study, AVariantKilledBetweenItsLastCheckpointAndItsSummaryIsFinishedFromThatCheckpoint) {
  // finish() writes the checkpoint at t_end, then summary.json: a variant killed in between left a
  // checkpoint with no time left, which every later call tried to continue and refused ("give a
  // later --set time.t_end"), exit 1, for ever.
  TempDir d;
  const fs::path out = d.path / "s";
  const std::string tiny = "study --levels 1,2 --set wall.model=membrane --set wall.law=nh --set flow.ca_s=0.2 "
                           "--set time.t_end=0.05 --threads 2 -o " + out.string();
  ASSERT_EQ(capsflow(tiny, d.path).code, 0);
  const fs::path l2 = out / "L2";
  const nlohmann::json before = json_of(l2 / "summary.json");
  const std::string series = slurp(l2 / "timeseries.csv");
  for (const std::string jobs : {"", " --jobs 2"}) {  // in this process, and in a child (--variant)
    fs::remove(l2 / "summary.json");
    const Result r = capsflow(tiny + jobs, d.path);
    ASSERT_EQ(r.code, 0) << jobs << "\n" << r.out;
    EXPECT_EQ(r.out.find("give a later"), std::string::npos) << r.out;
    const nlohmann::json after = json_of(l2 / "summary.json");
    EXPECT_EQ(after["stop_reason"], "t_end");
    EXPECT_EQ(after["run_id"], before["run_id"]);
    // The summary of the checkpoint's state, which is the state the killed run ended in: the same
    // numbers bit for bit (nothing is computed again), the same step and evaluation counts.
    for (const char* k : {"t", "steps", "rhs_evaluations", "D12", "D13", "D23", "L", "Le", "volume_drift"})
      EXPECT_EQ(after[k], before[k]) << jobs << ": " << k;
    EXPECT_EQ(slurp(l2 / "timeseries.csv"), series) << "no row was added or changed";
    for (const auto& v : json_of(out / "study.json")["variants"]) EXPECT_EQ(v["state"], "finished") << v["name"];
  }
}
