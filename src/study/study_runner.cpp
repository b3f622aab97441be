#include "capsflow/core/study/study_runner.hpp"

#include <fmt/core.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <thread>

#include "capsflow/core/driver/run.hpp"
#include "capsflow/core/io/checkpoint.hpp"
#include "capsflow/core/io/output_folder.hpp"
#include "capsflow/core/io/results_writer.hpp"
#include "capsflow/core/study/cost_model.hpp"
#include "capsflow/core/study/study_analysis.hpp"
#include "capsflow/core/study/study_report.hpp"

namespace capsflow::study {
namespace fs = std::filesystem;

namespace {

[[noreturn]] void fail(const std::string& msg) { throw std::runtime_error(msg); }

std::string quoted(const fs::path& p) { return "'" + p.string() + "'"; }

std::string hms(double s) {
  if (!std::isfinite(s) || s < 0) return "?";
  const long t = static_cast<long>(s + 0.5);
  return t >= 3600 ? fmt::format("{}h{:02}m", t / 3600, (t / 60) % 60) : fmt::format("{}m{:02}s", t / 60, t % 60);
}

// A study folder: new, empty, or one holding study.json (a study to continue). With overwrite,
// the study files are removed (the variants are run anew one by one); nothing else is.
void prepare_study_folder(const fs::path& dir, bool overwrite) {
  std::error_code ec;
  const fs::file_status st = fs::status(dir, ec);
  if (!fs::exists(st)) {
    fs::create_directories(dir, ec);
    if (ec) fail("cannot create study folder " + quoted(dir) + ": " + ec.message());
  } else if (!fs::is_directory(st)) {
    fail("output path " + quoted(dir) + " exists and is not a folder");
  } else if (!fs::is_empty(dir, ec) && !fs::exists(dir / kStudyJson, ec) && !overwrite) {
    fail("output folder " + quoted(dir) + " is not empty and holds no " + kStudyJson +
         " (not a study folder); pass --overwrite to use it anyway, or choose another -o");
  }
  io::check_writable(dir);
  if (!overwrite) return;
  for (const std::string& name : study_manifest()) {
    fs::remove(dir / name, ec);
    if (ec) fail("cannot remove " + quoted(dir / name) + ": " + ec.message());
  }
}

// Equal, numbers to 1e-12 relative: a scene that went through a checkpoint's canonical TOML
// has its derived numbers (ca_v = ca_s·thickness) recomputed, possibly one rounding apart.
bool same_value(const nlohmann::json& a, const nlohmann::json& b) {
  if (a.is_number() && b.is_number()) {
    const double x = a.get<double>(), y = b.get<double>();
    return std::abs(x - y) <= 1e-12 * std::max(std::abs(x), std::abs(y));
  }
  if (a.is_array() && b.is_array() && a.size() == b.size()) {
    for (std::size_t i = 0; i < a.size(); ++i)
      if (!same_value(a[i], b[i])) return false;
    return true;
  }
  return a == b;
}

// The first key (section.key) whose value differs between two resolved scenes, "" if none.
std::string first_difference(const nlohmann::json& a, const nlohmann::json& b) {
  for (const auto& [section, keys] : a.items()) {
    if (!b.contains(section)) return section;
    for (const auto& [key, value] : keys.items())
      if (!b[section].contains(key) || !same_value(b[section][key], value))
        return fmt::format("{}.{} ({} there, {} here)", section, key, b[section].contains(key) ? b[section][key].dump() : "absent",
                           value.dump());
  }
  for (const auto& [section, keys] : b.items())
    if (!a.contains(section)) return section;
  return "";
}

// Refuses a variant folder holding a run of another scene (another study, or changed --set).
void check_same_scene(const Variant& v, const fs::path& folder, const nlohmann::json& stored) {
  const std::string diff = first_difference(to_json(v.scene), stored);
  if (!diff.empty())
    fail(quoted(folder) + " holds a run of another scene (" + diff + "); pass --overwrite to run the variant " + v.name +
         " again, or choose another -o");
}

std::string result_line(const VariantResult& r) {
  const auto& f = r.final_values;
  return fmt::format("{} at t = {:g}, {} elements, {} evaluations in {} ({:.1f} ms each), D12 {:.5f} D13 {:.5f} D23 {:.5f}, "
                     "Le {:.4f} {:.4f} {:.4f}, dV/V {:+.1e}, peak {:.0f} MB",
                     r.stop_reason, r.t_final, r.elements, r.rhs_evaluations, hms(r.wall_seconds), 1e3 * r.seconds_per_evaluation,
                     f.at("D12"), f.at("D13"), f.at("D23"), f.at("Le1"), f.at("Le2"), f.at("Le3"), f.at("volume_drift"),
                     r.peak_rss_mb);
}

// While a variant runs (its own status lines hidden), a line every `interval` seconds with the
// time it has reached, read from the last complete row of its timeseries.csv.
class Heartbeat {
 public:
  Heartbeat(std::string tag, fs::path csv, double t_end, double interval)
      : tag_(std::move(tag)), csv_(std::move(csv)), t_end_(t_end), interval_(interval), thread_([this] { loop(); }) {}
  ~Heartbeat() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    thread_.join();
  }

 private:
  void loop() {
    const auto start = std::chrono::steady_clock::now();
    const double t_start = last_time();  // > 0 when the variant continues from a checkpoint
    std::unique_lock<std::mutex> lock(mutex_);
    while (!wake_.wait_for(lock, std::chrono::duration<double>(interval_), [this] { return stop_; })) {
      const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      const double t = last_time();
      // The remaining time at this segment's pace (RKC's steps vary: a rough figure).
      log_->info("{}: t = {:g} of {:g} after {}{}", tag_, t, t_end_, hms(elapsed),
                   t > t_start ? fmt::format(" (about {} more)", hms(elapsed * (t_end_ - t) / (t - t_start))) : std::string());
    }
  }
  double last_time() const {
    std::ifstream in(csv_);
    std::string line, last;
    std::getline(in, line);  // header
    while (std::getline(in, line))
      if (!in.eof()) last = line;  // a line without its newline may be half written
    return last.empty() ? 0.0 : std::strtod(last.c_str(), nullptr);  // t is the first column
  }

  // The runs' info lines are switched off on the default logger (QuietRuns): this one shares its
  // sinks (same terminal, same format) but not its level.
  std::shared_ptr<spdlog::logger> log_ =
      std::make_shared<spdlog::logger>("", spdlog::default_logger()->sinks().begin(), spdlog::default_logger()->sinks().end());
  std::string tag_;
  fs::path csv_;
  double t_end_, interval_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  std::thread thread_;  // last: started once the members above exist
};

// Keeps the runs' own info lines out of the study's output unless --verbose.
class QuietRuns {
 public:
  explicit QuietRuns(bool verbose) : saved_(spdlog::default_logger()->level()) {
    if (!verbose) spdlog::default_logger()->set_level(spdlog::level::warn);
  }
  ~QuietRuns() { spdlog::default_logger()->set_level(saved_); }

 private:
  spdlog::level::level_enum saved_;
};

}  // namespace

int run_study(const StudyOptions& o) {
  const StudyPlan plan = make_study_plan(o.scene_path, o.overrides, o.levels, o.vary);
  prepare_study_folder(o.dir, o.overwrite);
  const std::size_t n = plan.variants.size();
  std::vector<VariantRecord> records(n);
  std::vector<bool> resume(n, false);
  auto folder = [&](std::size_t i) { return o.dir / plan.variants[i].name; };

  // What each variant's folder holds, checked before anything runs.
  for (std::size_t i = 0; i < n && !o.overwrite; ++i) {
    const Variant& v = plan.variants[i];
    const FolderInspection f = inspect_variant_folder(folder(i));
    if (f.state == FolderState::Finished || f.state == FolderState::Failed) {
      VariantResult r = read_variant_result(folder(i));
      check_same_scene(v, folder(i), r.summary.at("scene"));
      records[i].state = f.state == FolderState::Finished ? "finished" : "failed";
      records[i].result = std::move(r);
    } else if (f.state == FolderState::Interrupted) {
      std::string scene_toml;
      try {
        scene_toml = io::read_checkpoint(io::find_latest_checkpoint(folder(i))).scene_toml;
      } catch (const std::runtime_error& e) {
        spdlog::warn("study: {}: no usable checkpoint ({}): running it again from the start", v.name, e.what());
        continue;
      }
      check_same_scene(v, folder(i), to_json(parse_scene(scene_toml, "checkpoint")));
      resume[i] = true;
      records[i].state = "interrupted";
    }
  }
  const bool rkc = plan.variants.front().scene.time.scheme == TimeScheme::Rkc;
  CostModel cost(rkc ? 1.5 : 2.0);
  std::size_t finished_before = 0, failed_before = 0, to_resume = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (records[i].state == "finished") ++finished_before;
    if (records[i].state == "failed") ++failed_before;
    if (resume[i]) ++to_resume;
    if (records[i].result && records[i].state == "finished")
      cost.add(plan.variants[i].family, records[i].result->elements, records[i].result->wall_seconds);
  }
  auto write_reports = [&] {
    const StudyAnalysis analysis = analyse_study(plan, records);
    write_study_reports(o.dir, StudyReport{plan, records, analysis, o.command_line});
  };
  write_reports();
  spdlog::info("study: {} variants (levels {}–{} × {} famil{}) in {}: {} finished earlier, {} failed earlier, {} to continue, {} to run",
               n, plan.levels.front(), plan.levels.back(), plan.families.size(), plan.families.size() == 1 ? "y" : "ies",
               o.dir.string(), finished_before, failed_before, to_resume, n - finished_before - failed_before - to_resume);

  auto remaining_seconds = [&](std::size_t after) {
    double s = 0;
    for (std::size_t j = after; j < n; ++j)
      if (records[j].state != "finished" && records[j].state != "failed")
        s += cost.predict(plan.variants[j].family, plan.variants[j].elements);
    return s;
  };
  auto eta = [&](std::size_t after) {
    std::size_t left = 0;
    for (std::size_t j = after; j < n; ++j) left += records[j].state != "finished" && records[j].state != "failed";
    if (left == 0) return std::string("done");
    const std::string growth =
        fmt::format("time ∝ N^{:.2f}{}", cost.exponent(), cost.fitted() ? " fitted" : rkc ? " assumed (RKC)" : " assumed (Heun)");
    return fmt::format("ETA {} for {} more ({})", hms(remaining_seconds(after)), left, growth);
  };

  int failed = static_cast<int>(failed_before);
  for (std::size_t i = 0; i < n; ++i) {
    const Variant& v = plan.variants[i];
    const std::string tag = fmt::format("study [{}/{}] {}", i + 1, n, v.name);
    if (records[i].state == "finished") {
      spdlog::info("{}: finished earlier: {}", tag, result_line(*records[i].result));
      continue;
    }
    if (records[i].state == "failed") {
      spdlog::warn("{}: stopped earlier with {}; not run again (delete {} or pass --overwrite to retry)", tag,
                   records[i].result->stop_reason, folder(i).string());
      continue;
    }
    RunOptions ro;
    ro.threads = o.threads;
    ro.command_line = o.command_line + "  # variant " + v.name;
    if (resume[i]) {
      ro.restart = folder(i).string();  // its checkpoint.h5 (or the previous one); continues in place
      ro.output_dir.clear();
      spdlog::info("{}: continuing from its checkpoint ({} elements)", tag, v.elements);
    } else {
      ro.scene = v.scene;
      ro.output_dir = folder(i).string();
      ro.overwrite = true;  // the variant's own folder: removes only capsflow's files of an unfinished run
      const double predicted = cost.predict(v.family, v.elements);
      spdlog::info("{}: running ({} elements{})", tag, v.elements,
                   predicted > 0 ? ", expected " + hms(predicted) : std::string());
    }
    int code = 0;
    try {
      QuietRuns quiet(o.verbose);
      std::unique_ptr<Heartbeat> heartbeat;
      if (!o.verbose)
        heartbeat = std::make_unique<Heartbeat>(tag, folder(i) / io::kTimeseriesCsv, v.scene.time.t_end, o.heartbeat_seconds);
      code = run_simulation(ro);
    } catch (const std::exception& e) {
      records[i].state = "error";
      write_reports();
      fail(fmt::format("variant {}: {}", v.name, e.what()));
    }
    if (code == 130) {
      records[i].state = "interrupted";
      write_reports();
      spdlog::warn("study: interrupted during {}; run the same command again to continue from its checkpoint", v.name);
      return 130;
    }
    VariantResult r = read_variant_result(folder(i));
    records[i].state = code == 0 ? "finished" : "failed";
    if (code == 0) {
      cost.add(v.family, r.elements, r.wall_seconds);
      spdlog::info("{}: {}; {}", tag, result_line(r), eta(i + 1));
    } else {
      ++failed;
      spdlog::warn("{}: stopped with {} (exit {}); the analysis uses the other variants; {}", tag, r.stop_reason, code, eta(i + 1));
    }
    records[i].result = std::move(r);
    write_reports();
  }
  spdlog::info("study: done: {} of {} variants finished{}; results in {}, {}, {}", n - failed, n,
               failed ? fmt::format(", {} stopped numerically", failed) : std::string(), (o.dir / kStudyMarkdown).string(),
               (o.dir / kStudyCsv).string(), (o.dir / kStudyJson).string());
  return failed ? 3 : 0;
}

}  // namespace capsflow::study
