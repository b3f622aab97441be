#include "capsflow/core/study/variant_run.hpp"

#include <fmt/core.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <mutex>
#include <thread>

#include "capsflow/core/driver/run.hpp"
#include "capsflow/core/io/results_writer.hpp"

namespace capsflow::study {
namespace fs = std::filesystem;

std::string hms(double s) {
  if (!std::isfinite(s) || s < 0) return "?";
  const long t = static_cast<long>(s + 0.5);
  return t >= 3600 ? fmt::format("{}h{:02}m", t / 3600, (t / 60) % 60) : fmt::format("{}m{:02}s", t / 60, t % 60);
}

std::string result_line(const VariantResult& r) {
  const auto& f = r.final_values;
  return fmt::format("{} at t = {:g}, {} elements, {} evaluations in {} ({:.1f} ms each), D12 {:.5f} D13 {:.5f} D23 {:.5f}, "
                     "Le {:.4f} {:.4f} {:.4f}, dV/V {:+.1e}, peak {:.0f} MB",
                     r.stop.to_string(), r.t_final, r.elements, r.rhs_evaluations, hms(r.wall_seconds), 1e3 * r.seconds_per_evaluation,
                     f.at("D12"), f.at("D13"), f.at("D23"), f.at("Le1"), f.at("Le2"), f.at("Le3"), f.at("volume_drift"),
                     r.peak_rss_mb);
}

namespace {

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

int run_variant(const Variant& v, const fs::path& folder, bool resume, const VariantRunOptions& o) {
  RunOptions ro;
  ro.threads = o.threads;
  ro.command_line = o.command_line + "  # variant " + v.name;
  if (resume) {
    ro.restart = folder.string();  // its checkpoint.h5 (or the previous one); continues in place
    ro.output_dir.clear();
    // Killed after its last checkpoint (the one finish() writes at t_end) and before summary.json:
    // the restart writes the summary from that checkpoint instead of refusing a run with no time left.
    ro.finish_at_t_end = true;
  } else {
    ro.scene = v.scene;
    ro.output_dir = folder.string();
    ro.overwrite = true;  // the variant's own folder: removes only capsflow's files of an unfinished run
  }
  QuietRuns quiet(o.verbose);
  std::unique_ptr<Heartbeat> heartbeat;
  if (!o.verbose) heartbeat = std::make_unique<Heartbeat>(o.tag, folder / io::kTimeseriesCsv, v.scene.time.t_end, o.heartbeat_seconds);
  return run_simulation(ro);
}

}  // namespace capsflow::study
