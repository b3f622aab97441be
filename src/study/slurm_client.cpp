#include "capsflow/core/study/slurm_client.hpp"

#include <cctype>
#include <sstream>
#include <stdexcept>

#include "capsflow/core/study/subprocess.hpp"

namespace capsflow::study {

namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\n"), e = s.find_last_not_of(" \t\r\n");
  return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
}

std::string field(const std::string& text, const std::string& key) {
  const std::string k = " " + key + "=";
  const std::string padded = " " + text;
  const auto at = padded.find(k);
  if (at == std::string::npos) return "";
  const auto start = at + k.size(), end = padded.find_first_of(" \n", start);
  return padded.substr(start, end == std::string::npos ? std::string::npos : end - start);
}

}  // namespace

std::optional<std::string> parse_sbatch_job_id(const std::string& out) {
  std::string id = trim(out);
  id = id.substr(0, id.find(';'));
  if (id.empty() || id.find_first_not_of("0123456789") != std::string::npos) return std::nullopt;
  return id;
}

std::map<std::string, QueueState> parse_squeue(const std::string& out) {
  std::map<std::string, QueueState> jobs;
  std::istringstream in(out);
  for (std::string line; std::getline(in, line);) {
    const auto bar = line.find('|');
    if (bar == std::string::npos) continue;
    const std::string id = trim(line.substr(0, bar)), state = trim(line.substr(bar + 1));
    if (state == "PENDING" || state == "REQUEUED" || state == "REQUEUE_HOLD" || state == "REQUEUE_FED" || state == "RESV_DEL_HOLD" ||
        state == "CONFIGURING")
      jobs[id] = QueueState::Queued;
    else if (state == "RUNNING" || state == "COMPLETING" || state == "SUSPENDED" || state == "STOPPED" || state == "RESIZING" ||
             state == "SIGNALING" || state == "STAGE_OUT")
      jobs[id] = QueueState::Running;
  }
  return jobs;
}

std::string parse_scontrol_job(const std::string& out) {
  const std::string state = field(out, "JobState");
  if (state.empty()) return "";
  const std::string code = field(out, "ExitCode");
  return code.empty() ? state : state + ", exit " + code;
}

std::string first_error_line(const std::string& err) {
  std::istringstream in(err);
  std::string line, first;
  while (std::getline(in, line)) {
    line = trim(line);
    if (line.empty()) continue;
    for (const char* prefix : {"sbatch: error: ", "squeue: error: ", "sbatch: ", "squeue: "})
      if (line.rfind(prefix, 0) == 0) line = line.substr(std::string(prefix).size());
    if (first.empty()) first = line;
    if (line.find("rror") != std::string::npos || line.find("nvalid") != std::string::npos) return line;
  }
  return first;
}

SlurmClient::SlurmClient() {
  for (const char* p : {"sbatch", "squeue"})
    if (!find_program(p))
      throw std::runtime_error(std::string("--scheduler slurm: ") + p + " is not on PATH (run on a Slurm login node, or load its module)");
}

std::string SlurmClient::submit(const std::vector<std::string>& options, const std::string& script, bool test_only) const {
  std::vector<std::string> argv = {"sbatch", test_only ? "--test-only" : "--parsable"};
  argv.insert(argv.end(), options.begin(), options.end());
  const ProcessOutput r = run_process(argv, script);
  if (r.exit_code != 0) {
    const std::string why = first_error_line(r.err.empty() ? r.out : r.err);
    throw std::runtime_error("sbatch refused the " + std::string(test_only ? "study's jobs" : "submission") + ": " +
                             (why.empty() ? "exit " + std::to_string(r.exit_code) : why));
  }
  if (test_only) return "";
  const auto id = parse_sbatch_job_id(r.out);
  if (!id) throw std::runtime_error("sbatch answered '" + trim(r.out) + "' instead of a job id");
  return *id;
}

std::map<std::string, QueueState> SlurmClient::active(const std::vector<std::string>& job_ids) const {
  if (job_ids.empty()) return {};
  std::string list;
  for (const std::string& j : job_ids) list += (list.empty() ? "" : ",") + j;
  const ProcessOutput r = run_process({"squeue", "-h", "-r", "-o", "%i|%T", "--jobs=" + list});
  // Every job unknown to slurmctld (finished long ago): squeue says so and exits 1.
  if (r.exit_code != 0 && r.err.find("Invalid job id") != std::string::npos) return {};
  if (r.exit_code != 0)
    throw std::runtime_error("cannot read the Slurm queue (squeue: " + first_error_line(r.err) + ")");
  return parse_squeue(r.out);
}

std::string SlurmClient::ended(const std::string& job_id) const {
  if (!find_program("scontrol")) return "";
  const ProcessOutput r = run_process({"scontrol", "show", "job", "-o", job_id});
  return r.exit_code == 0 ? parse_scontrol_job(r.out) : "";
}

void SlurmClient::cancel(const std::string& job_id) const {
  if (find_program("scancel")) run_process({"scancel", job_id});
}

}  // namespace capsflow::study
