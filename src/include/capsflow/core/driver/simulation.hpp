#pragma once
// One capsule simulation, step by step (docs/time-integration.md §5, docs/scene-and-output.md §3):
//
//   Simulation sim(options);
//   sim.set_up();                  // scene or checkpoint, output folder, right-hand side, scheme
//   while (!sim.step()) {}         // one accepted step each: health, outputs, checkpoints
//   const int code = sim.finish(); // last output, checkpoint and summary.json; the exit code
//
// run_simulation (run.hpp) is this loop with SIGINT/SIGTERM handled; a caller without signals
// (a binding, a test) stops a run with request_stop(), which is safe from a signal handler or
// another thread: the next step() returns "interrupted" before attempting anything.
#include <atomic>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>

#include "capsflow/core/driver/run.hpp"
#include "capsflow/core/driver/stop_reason.hpp"
#include "capsflow/core/types.hpp"

namespace capsflow {

class HealthMonitor;

// Simulation::set_up() ended by a stop request (request_stop, SIGINT/SIGTERM in run_simulation)
// before the run wrote its first state: the folder holds nothing of the run (a folder the set-up
// created is removed again, a restart's folder is as it was) and the lock is released. what() is
// the one-line message. A request that comes later in the set-up stops the run at its first step
// instead, as interrupted, with the checkpoint of its first state.
class SetUpInterrupted : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Simulation {
 public:
  explicit Simulation(RunOptions options);
  ~Simulation();
  Simulation(const Simulation&) = delete;
  Simulation& operator=(const Simulation&) = delete;

  // Everything before the first step; throws std::runtime_error (one line) for set-up errors.
  // Order: threads; restart plan or the new scene (refusals before any write); the output folder;
  // right-hand side, scheme, monitors; state from the checkpoint or the reference; the results
  // writer; the first output. A stop request is looked at between these parts: before the results
  // writer, it ends the set-up with SetUpInterrupted.
  void set_up();
  // One accepted step (rejected attempts are retried inside). Returns the reason once the run is
  // over — also when it already was; nullopt while it goes on.
  std::optional<StopReason> step();
  // The last output (unless the state was just written), the checkpoint, summary.json and the
  // closing log; releases the folder's lock (another run may continue it while this object is still
  // read); returns the exit code of the stop reason (t_end if the run was not stopped).
  // step() and finish() throw io::FolderLockLost before writing into a folder whose lock file was
  // removed or replaced under the run (io/folder_lock.hpp): the run ends there.
  int finish();
  // set_up, step until a stop, finish.
  int run();

  // `signal`: the signal that asked (logged), or 0 for a caller's request.
  void request_stop(int signal = 0) noexcept { stop_request_.store(signal > 0 ? signal : -1); }

  // The run as it stands (after set_up).
  double t() const;
  double dt() const;  // the last step taken
  long steps() const;
  long rhs_evaluations() const;  // the whole run, restarts included
  const Points& positions() const;
  const SurfaceMesh& reference() const;
  const std::filesystem::path& folder() const;
  const Points& load() const;  // q of the right-hand side's last evaluation (at the state after velocity())
  // F at the current state: the scheme's when its last evaluation was there, else evaluated now
  // (which moves the right-hand side's warm starts: the scheme then recomputes its own).
  const Points& velocity();
  const HealthMonitor& health() const;
  std::optional<StopReason> stop_reason() const;
  // A checkpoint of the current state at `path` (the run's own checkpoint.h5 is written by the
  // loop and by finish()); a run restarts from it with --restart. Refused (one line naming the
  // path, nothing written): one of this run's own files (io/manifest.hpp: run.h5, checkpoint.h5,
  // the lock file, ...) — std::invalid_argument; a folder another run holds locked — io::FolderBusy.
  void write_checkpoint(const std::filesystem::path& path);

 private:
  struct Impl;
  std::atomic<int> stop_request_{0};
  std::unique_ptr<Impl> impl_;
};

}  // namespace capsflow
