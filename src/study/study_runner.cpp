#include "capsflow/core/study/study_runner.hpp"

#include <fmt/core.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <fstream>
#include <optional>
#include <stdexcept>

#include "capsflow/core/study/cost_model.hpp"
#include "capsflow/core/study/local_jobs.hpp"
#include "capsflow/core/study/slurm_study.hpp"
#include "capsflow/core/study/study_analysis.hpp"
#include "capsflow/core/study/study_folder.hpp"
#include "capsflow/core/study/study_lock.hpp"
#include "capsflow/core/study/study_report.hpp"
#include "capsflow/core/study/variant_folder.hpp"
#include "capsflow/core/study/variant_run.hpp"

namespace capsflow::study {
namespace fs = std::filesystem;

namespace {

[[noreturn]] void fail(const std::string& msg) { throw std::runtime_error(msg); }

std::size_t count(const std::vector<VariantRecord>& records, VariantState s) {
  return static_cast<std::size_t>(std::count_if(records.begin(), records.end(), [s](const VariantRecord& r) { return r.state == s; }));
}

void write_reports(const StudyPlan& plan, const std::vector<VariantRecord>& records, const fs::path& dir,
                   const std::string& command_line) {
  const StudyAnalysis analysis = analyse_study(plan, records);
  write_study_reports(dir, StudyReport{plan, records, analysis, command_line});
}

// The closing line of a local study, and its exit code.
int done(const StudyPlan& plan, const std::vector<VariantRecord>& records, const fs::path& dir) {
  const std::size_t n = plan.variants.size(), failed = count(records, VariantState::Failed);
  spdlog::info("study: done: {} of {} variants finished{}; results in {}, {}, {}", count(records, VariantState::Finished), n,
               failed ? fmt::format(", {} stopped numerically", failed) : std::string(), (dir / kStudyMarkdown).string(),
               (dir / kStudyCsv).string(), (dir / kStudyJson).string());
  return failed ? 3 : 0;
}

// --jobs 1: the variants one after the other in this process, coarse to fine.
int run_sequentially(const StudyPlan& plan, const StudyOptions& o, std::vector<VariantRecord>& records) {
  const std::size_t n = plan.variants.size();
  CostModel cost = study_cost_model(plan, records);
  const bool rkc = is_stabilized(plan.variants.front().scene.time.scheme);
  auto open = [&](std::size_t j) { return records[j].state != VariantState::Finished && records[j].state != VariantState::Failed; };
  auto eta = [&](std::size_t after) {
    std::size_t left = 0;
    double s = 0;
    for (std::size_t j = after; j < n; ++j)
      if (open(j)) ++left, s += cost.predict(plan.variants[j].family, plan.variants[j].elements);
    if (left == 0) return std::string("done");
    const std::string growth =
        fmt::format("time ∝ N^{:.2f}{}", cost.exponent(), cost.fitted() ? " fitted" : rkc ? " assumed (stabilised)" : " assumed (Heun)");
    return fmt::format("ETA {} for {} more ({})", hms(s), left, growth);
  };
  for (std::size_t i = 0; i < n; ++i) {
    const Variant& v = plan.variants[i];
    const fs::path folder = o.dir / v.name;
    const std::string tag = fmt::format("study [{}/{}] {}", i + 1, n, v.name);
    if (records[i].state == VariantState::Finished) {
      spdlog::info("{}: finished earlier: {}", tag, result_line(*records[i].result));
      continue;
    }
    if (records[i].state == VariantState::Failed) {
      spdlog::warn("{}: stopped earlier with {}; not run again (delete {} or pass --overwrite to retry)", tag,
                   records[i].result->stop.to_string(), folder.string());
      continue;
    }
    const bool resume = records[i].state == VariantState::Interrupted;
    if (!records[i].note.empty()) spdlog::warn("{}: {}", tag, records[i].note);
    if (resume) {
      spdlog::info("{}: continuing from its checkpoint ({} elements)", tag, v.elements);
    } else {
      const double predicted = cost.predict(v.family, v.elements);
      spdlog::info("{}: running ({} elements{})", tag, v.elements, predicted > 0 ? ", expected " + hms(predicted) : std::string());
    }
    int code = 0;
    try {
      code = run_variant(v, folder, resume, VariantRunOptions{tag, o.threads, o.verbose, o.heartbeat_seconds, o.command_line});
    } catch (const std::exception& e) {
      records[i].state = VariantState::Error;
      records[i].note = e.what();
      write_reports(plan, records, o.dir, o.command_line);
      fail(fmt::format("variant {}: {}", v.name, e.what()));
    }
    if (code == 130) {
      records[i].state = VariantState::Interrupted;
      write_reports(plan, records, o.dir, o.command_line);
      spdlog::warn("study: interrupted during {}; run the same command again to continue from its checkpoint", v.name);
      return 130;
    }
    VariantResult r = read_variant_result(folder);
    records[i].state = r.stop.finished() ? VariantState::Finished : VariantState::Failed;  // as read back from the folder
    records[i].note.clear();
    if (r.stop.finished()) {
      cost.add(v.family, r.elements, r.wall_seconds);
      spdlog::info("{}: {}; {}", tag, result_line(r), eta(i + 1));
    } else {
      spdlog::warn("{}: stopped with {} (exit {}); the analysis uses the other variants; {}", tag, r.stop.to_string(), code, eta(i + 1));
    }
    records[i].result = std::move(r);
    write_reports(plan, records, o.dir, o.command_line);
  }
  return 0;
}

// --variant NAME: that variant only, as the loop above would run it; the study files are left to
// whoever collects (the analysis job, the parent of --jobs).
int run_one_variant(const StudyPlan& plan, const StudyOptions& o) {
  const auto it = std::find_if(plan.variants.begin(), plan.variants.end(), [&](const Variant& v) { return v.name == o.variant; });
  if (it == plan.variants.end()) {
    std::string names;
    for (const Variant& v : plan.variants) names += (names.empty() ? "" : ", ") + v.name;
    fail("--variant " + o.variant + ": no such variant in this study (" + names + ")");
  }
  const Variant& v = *it;
  const fs::path folder = o.dir / v.name;
  const VariantRecord rec = o.overwrite ? VariantRecord{} : read_variant_record(v, folder);
  const std::string tag = "study " + v.name;
  if (rec.state == VariantState::Finished) {
    spdlog::info("{}: finished earlier: {}", tag, result_line(*rec.result));
    return 0;
  }
  if (rec.state == VariantState::Failed) {
    spdlog::warn("{}: stopped earlier with {}; not run again", tag, rec.result->stop.to_string());
    return 3;
  }
  if (!rec.note.empty()) spdlog::warn("{}: {}", tag, rec.note);
  const bool resume = rec.state == VariantState::Interrupted;
  spdlog::info("{}: {} ({} elements, threads: {})", tag, resume ? "continuing from its checkpoint" : "running", v.elements,
               o.threads > 0 ? std::to_string(o.threads) : std::string("all cores"));
  const int code = run_variant(v, folder, resume, VariantRunOptions{tag, o.threads, o.verbose, o.heartbeat_seconds, o.command_line});
  if (code == 0 || code == 3) {
    const VariantResult r = read_variant_result(folder);
    (code == 0 ? spdlog::info("{}: {}", tag, result_line(r)) : spdlog::warn("{}: stopped with {}", tag, r.stop.to_string()));
  }
  return code;
}

struct RecordedStudy {
  StudyOptions options;
  std::optional<std::string> scene_text;  // absent in study.json files written before it was recorded
};

// The study recorded in DIR/study.json (the `study` block written by study_report).
RecordedStudy recorded_study(const fs::path& dir) {
  const fs::path p = dir / kStudyJson;
  require_regular_file(p);
  std::ifstream in(p);
  if (!in) fail("cannot read '" + p.string() + "': not a study folder");
  RecordedStudy r;
  StudyOptions& o = r.options;
  o.dir = dir;
  try {
    const nlohmann::json s = nlohmann::json::parse(in).at("study");
    const std::string scene = s.at("scene").get<std::string>();
    o.scene_path = scene == kBuiltInSceneName ? std::string() : scene;
    o.overrides = s.at("set").get<std::vector<std::string>>();
    o.levels = s.at("levels").get<std::vector<int>>();
    for (const auto& a : s.at("vary")) o.vary.push_back({a.at("key").get<std::string>(), a.at("values").get<std::vector<std::string>>()});
    o.command_line = s.value("command_line", std::string());
    if (s.contains("scene_text")) r.scene_text = s.at("scene_text").get<std::string>();
  } catch (const nlohmann::json::exception& e) {
    fail("'" + p.string() + "': not a study.json of this capsflow (" + e.what() + ")");
  }
  return r;
}

// The plan of a recorded study: from the scene text it recorded, or (an older study.json) from the
// scene file at the recorded path, which is relative to the folder the study was started in.
StudyPlan recorded_plan(const RecordedStudy& r) {
  const StudyOptions& o = r.options;
  if (r.scene_text) return make_study_plan_from_text(o.scene_path, *r.scene_text, o.overrides, o.levels, o.vary);
  std::error_code ec;
  if (!o.scene_path.empty() && !fs::exists(o.scene_path, ec))
    fail("study --analyse: " + (o.dir / kStudyJson).string() + " predates recorded scene texts and names the scene file '" +
         o.scene_path + "', which is not found from here: run --analyse from the folder the study was started in");
  return make_study_plan(o.scene_path, o.overrides, o.levels, o.vary);
}

}  // namespace

int run_study(const StudyOptions& o) {
  if (o.jobs < 1) fail(fmt::format("--jobs {}: must be at least 1", o.jobs));
  if (o.jobs > 1 && o.scheduler != Scheduler::Local) fail("--jobs: only with --scheduler local (Slurm runs one job per variant)");
  if (!o.slurm_options.empty() && o.scheduler != Scheduler::Slurm) fail("--slurm-opt: only with --scheduler slurm");
  const StudyPlan plan = make_study_plan(o.scene_path, o.overrides, o.levels, o.vary);
  if (!o.variant.empty()) return run_one_variant(plan, o);
  if (o.scheduler == Scheduler::Slurm) check_slurm_submission(o);  // before anything is written
  std::error_code ec;
  const bool new_folder = !fs::exists(o.dir, ec);
  // One study per folder at a time, for the whole study (its variants lock their own run folders).
  io::FolderLock lock = lock_study_folder(o.dir, o.scheduler == Scheduler::Slurm ? kSubmissionHolder : kLocalStudyHolder);
  prepare_study_folder(o.dir, o.overwrite);
  std::vector<VariantRecord> records(plan.variants.size());
  if (!o.overwrite) {
    check_same_study(plan, o.dir);
    records = read_variant_records(plan, o.dir);
  }
  if (o.scheduler == Scheduler::Local) {
    refuse_while_slurm_jobs_active(o.dir);
    // A Slurm submission replaces the study files once Slurm has accepted it: a refused one leaves them.
    if (o.overwrite) remove_study_files(o.dir);
  }
  if (o.scheduler == Scheduler::Slurm) {
    try {
      return submit_study(plan, o, records);
    } catch (const std::runtime_error&) {
      lock.release();
      if (new_folder && fs::is_empty(o.dir, ec)) fs::remove(o.dir, ec);  // refused before anything was written
      throw;
    }
  }

  write_reports(plan, records, o.dir, o.command_line);
  const std::size_t n = plan.variants.size(), finished = count(records, VariantState::Finished),
                    failed = count(records, VariantState::Failed), resume = count(records, VariantState::Interrupted);
  spdlog::info("study: {} variants (levels {}–{} × {} famil{}) in {}: {} finished earlier, {} failed earlier, {} to continue, {} to run{}",
               n, plan.levels.front(), plan.levels.back(), plan.families.size(), plan.families.size() == 1 ? "y" : "ies",
               o.dir.string(), finished, failed, resume, n - finished - failed - resume,
               o.jobs > 1 ? fmt::format(", {} at a time", o.jobs) : std::string());
  int code = 0;
  try {
    code = o.jobs > 1 ? run_local_jobs(plan, o, records) : run_sequentially(plan, o, records);
  } catch (const std::runtime_error&) {
    write_reports(plan, records, o.dir, o.command_line);  // what did finish stays analysed
    throw;
  }
  write_reports(plan, records, o.dir, o.command_line);  // interrupted too: each variant's state as its folder says
  if (code == 130) return code;
  return done(plan, records, o.dir);
}

int analyse_study_folder(const fs::path& dir) {
  const RecordedStudy recorded = recorded_study(dir);
  const StudyOptions& o = recorded.options;
  const io::FolderLock lock = lock_study_folder(dir, kAnalysisHolder);  // it rewrites the study's reports
  const StudyPlan plan = recorded_plan(recorded);
  std::vector<VariantRecord> records = read_variant_records(plan, dir);
  annotate_from_slurm_records(plan, dir, records);
  write_reports(plan, records, dir, o.command_line);
  const std::size_t finished = count(records, VariantState::Finished);
  std::string missing;
  for (std::size_t i = 0; i < records.size(); ++i)
    if (records[i].state != VariantState::Finished)
      missing += fmt::format("\n  {}: {}{}", plan.variants[i].name, to_string(records[i].state),
                             records[i].result ? " (" + records[i].result->stop.to_string() + ")"
                             : records[i].note.empty() ? std::string() : " (" + records[i].note + ")");
  spdlog::info("study --analyse {}: {} of {} variants finished, analysed in {}{}", dir.string(), finished, records.size(),
               (dir / kStudyMarkdown).string(), missing.empty() ? std::string() : "; missing:" + missing);
  return finished == records.size() ? 0 : 3;
}

}  // namespace capsflow::study
