#include "capsflow/core/study/slurm_study.hpp"

#include <fmt/core.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <ctime>
#include <fstream>
#include <map>
#include <stdexcept>

#include "capsflow/core/io/atomic_file.hpp"
#include "capsflow/core/study/cost_model.hpp"
#include "capsflow/core/study/slurm_client.hpp"
#include "capsflow/core/study/slurm_records.hpp"
#include "capsflow/core/study/slurm_script.hpp"
#include "capsflow/core/study/study_analysis.hpp"
#include "capsflow/core/study/study_report.hpp"
#include "capsflow/core/study/subprocess.hpp"
#include "capsflow/core/study/variant_run.hpp"

namespace capsflow::study {
namespace fs = std::filesystem;

namespace {

[[noreturn]] void fail(const std::string& msg) { throw std::runtime_error(msg); }

std::string now_utc() {
  const std::time_t t = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return buf;
}

// The last line of a job's log that reports an error (capsflow's "error:", Slurm's
// "slurmstepd: error: … CANCELLED … DUE TO TIME LIMIT"), else its last line; "" without a log.
std::string last_error_line(const fs::path& log) {
  std::ifstream in(log);
  std::string line, last, error;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    last = line;
    if (line.find("error") != std::string::npos || line.find("CANCELLED") != std::string::npos) error = line;
  }
  std::string s = error.empty() ? last : error;
  if (s.size() > 300) s = s.substr(0, 300) + "…";
  return s;
}

std::string array_job(const std::string& job) { return job.substr(0, job.find('_')); }

std::string join(const std::vector<std::string>& v, const char* sep = ", ") {
  std::string out;
  for (const std::string& s : v) out += (out.empty() ? "" : sep) + s;
  return out;
}

}  // namespace

void check_slurm_submission(const StudyOptions& o) {
  SlurmClient client;  // throws without sbatch / squeue
  check_site_options(o.slurm_options);
}

namespace {

// The study's recorded variant jobs still queued or running; empty when Slurm is not on PATH here.
std::map<std::string, QueueState> active_variant_jobs_here(const SlurmRecords& recs) {
  if (recs.variants.empty() || !find_program("sbatch") || !find_program("squeue")) return {};
  std::vector<std::string> ids;
  for (const auto& [name, v] : recs.variants) ids.push_back(v.job);
  return SlurmClient().active(ids);
}

}  // namespace

void annotate_from_slurm_records(const StudyPlan& plan, const fs::path& dir, std::vector<VariantRecord>& records) {
  const SlurmRecords recs = read_slurm_records(dir);
  std::map<std::string, QueueState> active;
  try {
    active = active_variant_jobs_here(recs);
  } catch (const std::runtime_error& e) {
    spdlog::warn("study --analyse: {}; the variants' states are read from their folders and logs only", e.what());
  }
  for (std::size_t i = 0; i < plan.variants.size(); ++i) {
    const auto it = recs.variants.find(plan.variants[i].name);
    if (records[i].result || it == recs.variants.end()) continue;
    if (const auto q = active.find(it->second.job); q != active.end()) {  // not an error: it has not ended
      records[i].state = q->second == QueueState::Queued ? VariantState::Queued : VariantState::Running;
      records[i].note = "job " + it->second.job;
      continue;
    }
    const std::string why = last_error_line(dir / it->second.log);
    if (records[i].state == VariantState::Pending) records[i].state = VariantState::Error;
    records[i].note = "job " + it->second.job + (why.empty() ? "" : ": " + why);
  }
}

void refuse_while_slurm_jobs_active(const fs::path& dir) {
  std::map<std::string, QueueState> active;
  try {
    active = active_variant_jobs_here(read_slurm_records(dir));
  } catch (const std::runtime_error& e) {
    fail(std::string(e.what()) + "; nothing run, as a variant still queued on Slurm could run twice");
  }
  std::vector<std::string> jobs;
  for (const auto& [job, state] : active) jobs.push_back(job);
  if (!jobs.empty())
    fail("jobs of this study are queued or running on Slurm (" + join(jobs) +
         ") and would write the same variant folders: wait for them or scancel them, or run the same command with "
         "--scheduler slurm to collect them");
}

int submit_study(const StudyPlan& plan, const StudyOptions& o, std::vector<VariantRecord>& records) {
  const SlurmClient client;
  SlurmRecords recs = read_slurm_records(o.dir);
  std::vector<std::string> ids;
  for (const auto& [name, v] : recs.variants) ids.push_back(v.job);
  if (!recs.analysis_job.empty()) ids.push_back(recs.analysis_job);
  std::map<std::string, QueueState> active;
  try {
    active = client.active(ids);  // before the folders: a job may end meanwhile
  } catch (const std::runtime_error& e) {
    fail(std::string(e.what()) + "; nothing submitted, as a variant still queued could be submitted twice");
  }
  std::vector<std::string> active_variant_jobs;
  for (const auto& [name, v] : recs.variants)
    if (active.count(v.job)) active_variant_jobs.push_back(v.job);
  if (o.overwrite && !active_variant_jobs.empty())
    fail("--overwrite: jobs of this study are queued or running (" + join(active_variant_jobs) +
         "); wait for them or scancel them first");

  // What each variant needs.
  const std::size_t n = plan.variants.size();
  std::vector<std::size_t> todo;
  std::vector<long> previous_minutes(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const Variant& v = plan.variants[i];
    const auto rec = recs.variants.find(v.name);
    const bool has_job = rec != recs.variants.end();
    if (!o.overwrite && has_job && active.count(rec->second.job)) {
      records[i].state = active.at(rec->second.job) == QueueState::Queued ? VariantState::Queued : VariantState::Running;
      records[i].note = "job " + rec->second.job;
      continue;
    }
    if (!o.overwrite && (records[i].state == VariantState::Finished || records[i].state == VariantState::Failed)) {
      if (records[i].state == VariantState::Failed)
        spdlog::warn("study {}: stopped earlier with {}; not submitted again (delete {} or pass --overwrite to retry)", v.name,
                     records[i].result->stop.to_string(), (o.dir / v.name).string());
      continue;
    }
    if (!o.overwrite && has_job) {
      const std::string ended = client.ended(rec->second.job);
      const std::string why = last_error_line(o.dir / rec->second.log);
      const std::string job = "job " + rec->second.job + (ended.empty() ? "" : " (" + ended + ")");
      // Killed at its limit before it could write a checkpoint (slurmctld's state while it remembers
      // the job, else slurmstepd's line in the log): the same limit would kill it again.
      const bool timed_out = ended.rfind("TIMEOUT", 0) == 0 || why.find("DUE TO TIME LIMIT") != std::string::npos;
      if (records[i].state == VariantState::Interrupted || timed_out) previous_minutes[i] = rec->second.minutes;
      if (records[i].state == VariantState::Interrupted) {
        spdlog::warn("study {}: {} stopped with a checkpoint{}; submitted again with more time, to continue from it", v.name, job,
                     why.empty() ? "" : " — " + why);
      } else {
        records[i].state = VariantState::Error;
        records[i].note = job + " ended without a result" + (why.empty() ? "" : ": " + why);
        spdlog::warn("study {}: {}; submitted again{}", v.name, records[i].note, timed_out ? " with more time" : "");
      }
    }
    todo.push_back(i);
  }

  const std::size_t queued = std::count_if(records.begin(), records.end(), [](const VariantRecord& r) { return r.state == VariantState::Queued; });
  const std::size_t running = std::count_if(records.begin(), records.end(), [](const VariantRecord& r) { return r.state == VariantState::Running; });
  if (todo.empty()) {
    const StudyAnalysis analysis = analyse_study(plan, records);
    write_study_reports(o.dir, StudyReport{plan, records, analysis, o.command_line});
    const std::size_t finished = std::count_if(records.begin(), records.end(), [](const VariantRecord& r) { return r.state == VariantState::Finished; });
    if (queued + running > 0) {
      spdlog::info("study: nothing to submit: {} finished, {} queued, {} running ({}); follow with: squeue -j {}", finished, queued,
                   running, join(active_variant_jobs), join(active_variant_jobs, ","));
      return 0;
    }
    spdlog::info("study: every variant has a result: {} of {} finished; analysed in {}", finished, n, (o.dir / kStudyMarkdown).string());
    return finished == n ? 0 : 3;
  }

  // Sizes, and one array job per size.
  const CostModel cost = study_cost_model(plan, records);
  std::vector<std::pair<JobSize, std::vector<ScriptVariant>>> groups;
  for (std::size_t i : todo) {
    const JobSize s = size_job(plan.variants[i], cost, o.threads, previous_minutes[i]);
    auto g = std::find_if(groups.begin(), groups.end(), [&](const auto& x) { return x.first == s; });
    if (g == groups.end()) g = groups.insert(groups.end(), {s, {}});
    g->second.push_back({i, &plan.variants[i], s});
  }
  std::vector<ScriptVariant> all;
  for (const auto& g : groups) all.insert(all.end(), g.second.begin(), g.second.end());
  const std::string exe = own_executable().string();
  const std::string script = variants_script(exe, o, plan, all), analysis = analysis_script(exe, o);
  auto group_options = [&](const JobSize& s, const std::vector<ScriptVariant>& vs) {
    std::string array;
    for (const ScriptVariant& v : vs) array += (array.empty() ? "" : ",") + std::to_string(v.index);
    std::vector<std::string> opts = {"--array=" + array};
    if (!site_sets(o.slurm_options, "--cpus-per-task", "-c")) opts.push_back(fmt::format("--cpus-per-task={}", s.threads));
    if (!site_sets(o.slurm_options, "--mem", "")) opts.push_back(fmt::format("--mem={}M", s.memory_mb));
    if (!site_sets(o.slurm_options, "--time", "-t")) opts.push_back(fmt::format("--time={}", s.minutes));
    return opts;
  };
  // Every submission checked before any is made: a site option or a size Slurm refuses submits nothing.
  for (const auto& [s, vs] : groups) client.submit(group_options(s, vs), script, true);
  client.submit({}, analysis, true);

  const fs::path slurm_dir = fs::absolute(o.dir).lexically_normal() / kSlurmFolder;
  std::error_code ec;
  fs::create_directories(slurm_dir, ec);
  if (ec) fail("cannot create '" + slurm_dir.string() + "': " + ec.message());
  io::write_file_atomically(slurm_dir / "variants.sh", script);
  io::write_file_atomically(slurm_dir / "analyse.sh", analysis);
  const std::vector<VariantRecord> before = records;  // what the study files say again if sbatch refuses below
  for (std::size_t i : todo) records[i].state = VariantState::Queued;
  auto write_reports = [&] { write_study_reports(o.dir, StudyReport{plan, records, analyse_study(plan, records), o.command_line}); };
  write_reports();  // study.json first: the analysis job reads it

  std::vector<std::string> submitted, dependencies = active_variant_jobs;
  for (std::string& d : dependencies) d = array_job(d);
  for (std::size_t g = 0; g < groups.size(); ++g) {
    const auto& [s, vs] = groups[g];
    std::vector<std::string> opts = group_options(s, vs);
    opts.push_back((slurm_dir / "variants.sh").string());
    std::string id;
    try {
      id = client.submit(opts, "", false);
    } catch (const std::runtime_error& e) {
      for (std::size_t k = g; k < groups.size(); ++k)
        for (const ScriptVariant& v : groups[k].second) records[v.index] = before[v.index];  // not queued after all
      write_reports();
      write_slurm_records(o.dir, recs);
      fail(std::string(e.what()) + (submitted.empty() ? "" : "; submitted before it: " + join(submitted) +
                                                                 " (run the same command again to submit the rest)"));
    }
    std::vector<std::string> names;
    for (const ScriptVariant& v : vs) {
      VariantJob& j = recs.variants[v.variant->name];
      j = {id + "_" + std::to_string(v.index), fmt::format("{}/variant-{}_{}.out", kSlurmFolder, id, v.index), s.minutes, s.threads,
           s.memory_mb, j.submissions + 1};
      names.push_back(v.variant->name);
      records[v.index].note = "job " + j.job;
    }
    recs.submissions.push_back({{"job", id}, {"kind", "variants"}, {"variants", names}, {"sbatch", opts}, {"at", now_utc()}});
    write_slurm_records(o.dir, recs);
    submitted.push_back(fmt::format("job {} ({}: {} thread{}, {} MB, {} min)", id, join(names), s.threads, s.threads == 1 ? "" : "s",
                                    s.memory_mb, s.minutes));
    dependencies.push_back(id);
  }
  // One analysis after all of them: a still-waiting earlier one would run too soon.
  if (!recs.analysis_job.empty() && active.count(recs.analysis_job) && active.at(recs.analysis_job) == QueueState::Queued)
    client.cancel(recs.analysis_job);
  std::vector<std::string> aopts = {"--dependency=afterany:" + join(dependencies, ":"), "--kill-on-invalid-dep=no",
                                    (slurm_dir / "analyse.sh").string()};
  const std::string aid = client.submit(aopts, "", false);
  recs.analysis_job = aid;
  recs.analysis_log = fmt::format("{}/analyse-{}.out", kSlurmFolder, aid);
  recs.submissions.push_back({{"job", aid}, {"kind", "analysis"}, {"sbatch", aopts}, {"at", now_utc()}});
  write_slurm_records(o.dir, recs);

  std::vector<std::string> all_ids = dependencies;
  all_ids.push_back(aid);
  spdlog::info("study: submitted {} variant{} to Slurm: {}; analysis: job {} (after them, whatever their outcome){}", todo.size(),
               todo.size() == 1 ? "" : "s", join(submitted, "; "), aid,
               queued + running ? fmt::format("; {} queued or running from before", queued + running) : std::string());
  spdlog::info("study: follow with `squeue -j {}`; logs in {}; results in {} when the analysis has run (or now: capsflow study "
               "--analyse {}); run the same command again to collect and resubmit what failed",
               join(all_ids, ","), slurm_dir.string(), (o.dir / kStudyMarkdown).string(), o.dir.string());
  return 0;
}

}  // namespace capsflow::study
