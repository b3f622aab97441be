#include "capsflow/core/study/local_jobs.hpp"

#include <fmt/core.h>
#include <signal.h>
#include <spdlog/spdlog.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <map>
#include <stdexcept>
#include <thread>

#include "capsflow/core/study/cost_model.hpp"
#include "capsflow/core/study/study_folder.hpp"
#include "capsflow/core/study/subprocess.hpp"
#include "capsflow/core/study/variant_command.hpp"

namespace capsflow::study {
namespace fs = std::filesystem;

namespace {

volatile sig_atomic_t g_stop_signal = 0;       // the last SIGINT/SIGTERM received
volatile sig_atomic_t g_stop_count = 0;        // how many were received
volatile sig_atomic_t g_stop_from_terminal = 0;  // the last one came from the terminal (Ctrl-C)
extern "C" void remember_stop(int sig, siginfo_t* info, void*) {
  g_stop_signal = sig;
  g_stop_from_terminal = info != nullptr && info->si_code == SI_KERNEL;
  g_stop_count = g_stop_count + 1;
}

// SIGINT/SIGTERM recorded instead of ending this process while children run; restored after.
class StopSignals {
 public:
  StopSignals() {
    g_stop_signal = 0;
    g_stop_count = 0;
    g_stop_from_terminal = 0;
    struct sigaction sa {};
    sa.sa_sigaction = remember_stop;
    sa.sa_flags = SA_SIGINFO;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, &old_int_);
    sigaction(SIGTERM, &sa, &old_term_);
  }
  ~StopSignals() {
    sigaction(SIGINT, &old_int_, nullptr);
    sigaction(SIGTERM, &old_term_, nullptr);
  }

 private:
  struct sigaction old_int_ {}, old_term_ {};
};

bool open_variant(const VariantRecord& r) { return r.state != VariantState::Finished && r.state != VariantState::Failed; }

}  // namespace

std::vector<std::size_t> local_job_order(const StudyPlan& plan, const std::vector<VariantRecord>& records) {
  const CostModel cost = study_cost_model(plan, records);
  std::vector<std::pair<double, std::size_t>> keyed;
  for (std::size_t i = 0; i < plan.variants.size(); ++i) {
    if (!open_variant(records[i])) continue;
    const Variant& v = plan.variants[i];
    const double measured = cost.predict(v.family, v.elements);
    keyed.emplace_back(measured > 0 ? measured : std::pow(static_cast<double>(v.elements), cost.exponent()), i);
  }
  std::stable_sort(keyed.begin(), keyed.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  std::vector<std::size_t> order;
  for (const auto& k : keyed) order.push_back(k.second);
  return order;
}

int run_local_jobs(const StudyPlan& plan, const StudyOptions& o, std::vector<VariantRecord>& records) {
  const std::vector<std::size_t> order = local_job_order(plan, records);
  const int total = o.threads > 0 ? o.threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const int threads = std::max(1, total / o.jobs);
  const std::string exe = own_executable().string();
  const std::size_t n = plan.variants.size();
  std::string listed;
  for (std::size_t i : order) listed += (listed.empty() ? "" : ", ") + plan.variants[i].name;
  spdlog::info("study: {} at a time with {} thread{} each, longest predicted first: {}", o.jobs, threads, threads == 1 ? "" : "s",
               listed.empty() ? "nothing to run" : listed);

  StopSignals signals;
  std::map<pid_t, std::size_t> running;
  std::vector<std::string> errors;
  std::size_t next = 0;
  int signals_seen = 0;
  // A stop request starts no new variant: the loop ends once the running ones have ended.
  while ((!g_stop_count && next < order.size()) || !running.empty()) {
    if (g_stop_count != signals_seen) {
      const bool first = signals_seen == 0 && g_stop_count == 1;
      signals_seen = g_stop_count;
      // The first signal is passed on (a Ctrl-C reached the children already, through the
      // terminal's process group): they write a checkpoint and stop. A second one stops them at
      // once; their last checkpoints stay (written atomically).
      if (!first || !g_stop_from_terminal)
        for (const auto& [pid, i] : running) ::kill(pid, first ? static_cast<int>(g_stop_signal) : SIGKILL);
      const bool one = running.size() == 1;
      spdlog::warn("study: signal {} received{}: no further variant starts; {} running {}", static_cast<int>(g_stop_signal),
                   first ? "" : " again", one ? std::string("the") : fmt::format("the {}", running.size()),
                   first ? (one ? "variant stops with a checkpoint" : "variants stop with a checkpoint")
                         : (one ? "variant is stopped at once, keeping its last checkpoint"
                                : "variants are stopped at once, keeping their last checkpoints"));
    }
    while (!g_stop_count && next < order.size() && running.size() < static_cast<std::size_t>(o.jobs)) {
      const std::size_t i = order[next++];
      running[start_process(variant_command(exe, o, plan.variants[i].name, threads))] = i;
      records[i].state = VariantState::Running;
      spdlog::info("study [{}/{}] {}: started ({} elements)", i + 1, n, plan.variants[i].name, plan.variants[i].elements);
    }
    int status = 0;
    const pid_t pid = ::waitpid(-1, &status, WNOHANG);
    if (pid <= 0 || !running.count(pid)) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      continue;
    }
    const std::size_t i = running.at(pid);
    running.erase(pid);
    const Variant& v = plan.variants[i];
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
    records[i] = read_variant_record(v, o.dir / v.name);
    // Stopped by the request (exit 130, or killed after a second signal): its folder says where it
    // stands — interrupted with a checkpoint, or pending when it had written none.
    const bool stopped = g_stop_count && (code == 130 || WIFSIGNALED(status));
    if (code != 0 && code != 3 && !stopped && records[i].state != VariantState::Interrupted) {
      records[i].state = VariantState::Error;
      records[i].note = fmt::format("exit {} (its message is above)", code);
      errors.push_back(fmt::format("variant {}: exit {}", v.name, code));
    }
    std::size_t left = 0;
    for (std::size_t j = 0; j < n; ++j) left += open_variant(records[j]) && records[j].state != VariantState::Running;
    // The child printed the variant's own result line; this one says where the study stands.
    spdlog::info("study [{}/{}] {}: {}{}; {} running, {} waiting", i + 1, n, v.name, to_string(records[i].state),
                 records[i].state == VariantState::Failed ? " (" + records[i].result->stop.to_string() + ")" : std::string(),
                 running.size(), left);
  }
  if (g_stop_count) {
    spdlog::warn("study: interrupted; run the same command again to continue the variants from their checkpoints");
    return 130;
  }
  if (!errors.empty()) {
    std::string all;
    for (const std::string& e : errors) all += (all.empty() ? "" : "; ") + e;
    throw std::runtime_error(all);
  }
  return 0;
}

}  // namespace capsflow::study
