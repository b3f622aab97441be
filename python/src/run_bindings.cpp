// Runs: the driver's public Simulation (driver/simulation.hpp) behind capsflow.run and
// capsflow.Simulation (python/capsflow/run.py checks the arguments and documents them).
//
// The GIL is released while C++ computes (set-up, each step, finish). No signal handler is
// installed: Python keeps its own SIGINT handler, which only sets a flag while C++ runs; after each
// step and at each status line (the progress callback's cadence) the flag is polled with
// PyErr_CheckSignals, and a KeyboardInterrupt — or any exception of the progress callback — asks
// the Simulation to stop (request_stop): its next step returns "interrupted", finish() writes the
// checkpoint and summary.json as on SIGINT on the command line, and the exception is raised after.
//
// The callback runs inside step() or finish(): from there, step(), run_to_end() and finish() are
// refused with a RuntimeError (which, like any exception of the callback, stops the run as
// interrupted), so a callback cannot re-enter the run it reports on — finish() called from the
// callback of finish()'s own status line would recurse until the stack overflowed, in the middle
// of writing a checkpoint. A callback that wants the run to end calls request_stop().
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <omp.h>
#include <spdlog/spdlog.h>

#include "bindings.hpp"
#include "capsflow/core/driver/run.hpp"
#include "capsflow/core/driver/simulation.hpp"
#include "capsflow/core/driver/stop_reason.hpp"
#include "capsflow/core/driver/thread_count.hpp"
#include "capsflow/core/health/health_monitor.hpp"
#include "capsflow/core/io/io_error.hpp"
#include "capsflow/core/mesh/topology.hpp"
#include "capsflow/core/scene/scene.hpp"

namespace py = pybind11;

namespace capsflow::python {
namespace {

// A copy of an (N, 3) row-major matrix as a new numpy array (the state changes under a view).
py::array_t<double> copy_points(const Points& p) {
  py::array_t<double> a({static_cast<py::ssize_t>(p.rows()), static_cast<py::ssize_t>(3)});
  std::copy(p.data(), p.data() + p.size(), a.mutable_data());
  return a;
}

// A read-only view of a matrix that lives as long as `owner` (the reference mesh never changes
// after set-up).
template <class Matrix>
py::array read_only_view(const Matrix& m, py::handle owner) {
  using T = typename Matrix::Scalar;
  py::array_t<T> a({static_cast<py::ssize_t>(m.rows()), static_cast<py::ssize_t>(m.cols())},
                   {static_cast<py::ssize_t>(m.cols() * sizeof(T)), static_cast<py::ssize_t>(sizeof(T))}, m.data(), owner);
  py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return std::move(a);
}

// One Simulation and the Python side of it: the progress callback and the exception that stopped
// the run (a KeyboardInterrupt, or the callback's own), raised once the run is finished.
class PySimulation {
 public:
  PySimulation(const std::optional<Scene>& scene, std::string output_dir, bool overwrite, std::string restart,
               std::vector<std::string> restart_overrides, int threads, double progress_interval, py::object progress,
               std::string command_line)
      : progress_(std::move(progress)), threads_before_(omp_get_max_threads()) {
    // libgomp ends the process when it cannot start a thread: refused here, before any folder is locked.
    check_thread_count(threads, "threads = " + std::to_string(threads));
    RunOptions o;
    if (scene) o.scene = *scene;
    o.output_dir = std::move(output_dir);
    o.overwrite = overwrite;
    o.restart = std::move(restart);
    o.restart_overrides = std::move(restart_overrides);
    o.threads = threads;
    o.progress_interval = progress_interval;
    o.command_line = std::move(command_line);
    if (!progress_.is_none()) o.on_progress = [this](const RunProgress& p) { on_progress(p); };
    sim_ = std::make_unique<Simulation>(std::move(o));
    try {
      py::gil_scoped_release nogil;
      sim_->set_up();
    } catch (const io::IoError&) {
      restore_threads();
      throw;  // OSError (errors.cpp)
    } catch (const SetUpInterrupted&) {
      restore_threads();
      throw;  // a stop request during the set-up: RuntimeError, not bad input
    } catch (const std::runtime_error& e) {
      restore_threads();
      // Set-up refuses its input (a scene, a mesh, a restart into the wrong folder) with one line:
      // what --restart or the scene got wrong, as the command line prints it.
      throw py::value_error(e.what());
    } catch (...) {
      restore_threads();
      throw;
    }
    poll();  // a Ctrl-C during set-up stops before the first step
  }

  ~PySimulation() { restore_threads(); }

  // One step; the stop reason once the run is over (also when it already was), else None.
  std::optional<std::string> step() {
    refuse_in_callback("step()");
    std::optional<StopReason> r;
    {
      py::gil_scoped_release nogil;
      r = sim_->step();
    }
    poll();
    if (r) return r->to_string();
    return std::nullopt;
  }

  // step() until the run stops; the stop reason.
  std::string run_to_end() {
    refuse_in_callback("run_to_end()");
    for (;;) {
      std::optional<StopReason> r;
      {
        py::gil_scoped_release nogil;
        r = sim_->step();
      }
      poll();
      if (r) return r->to_string();
    }
  }

  // Stop (as interrupted) if the run is not over, then the last output, checkpoint, summary.json;
  // the exit code. Raises the exception that stopped the run, if any, afterwards.
  int finish() {
    refuse_in_callback("finish()");
    if (finished_) throw std::logic_error("finish() was called already: the run is over");
    if (!sim_->stop_reason()) {
      sim_->request_stop();
      py::gil_scoped_release nogil;
      sim_->step();  // returns "interrupted" before attempting anything
    }
    int code = 0;
    {
      py::gil_scoped_release nogil;
      code = sim_->finish();
    }
    finished_ = true;
    restore_threads();
    raise_pending();
    return code;
  }

  void request_stop() { sim_->request_stop(); }
  bool finished() const { return finished_; }
  std::optional<std::string> stop_reason() const {
    const auto r = sim_->stop_reason();
    return r ? std::optional<std::string>(r->to_string()) : std::nullopt;
  }
  // The exception that stopped the run and has not been raised yet (finish() raises it).
  bool has_pending() const { return static_cast<bool>(pending_); }
  void raise_pending() {
    if (!pending_) return;
    std::unique_ptr<py::error_already_set> e = std::move(pending_);
    e->restore();
    throw py::error_already_set();
  }

  Simulation& sim() { return *sim_; }

  // Refuses to enter the run from its own progress callback (see the top of this file).
  void refuse_in_callback(const char* what) const {
    if (in_callback_)
      throw std::logic_error(std::string(what) + " cannot be called from the progress callback, which runs inside step() "
                             "and finish(): call request_stop() there, and finish() after the step returns");
  }

 private:
  // A pending signal (KeyboardInterrupt from Python's SIGINT handler) stops the run; the error is
  // kept for finish() to raise.
  void poll() {
    if (PyErr_CheckSignals() != 0) keep_and_stop(py::error_already_set());
  }

  void keep_and_stop(py::error_already_set e) {
    if (!pending_) pending_ = std::make_unique<py::error_already_set>(std::move(e));
    sim_->request_stop();
  }

  // Called by the Simulation at each status line, from the thread running step() or finish()
  // (which released the GIL).
  void on_progress(const RunProgress& p) {
    py::gil_scoped_acquire gil;
    if (pending_) return;  // stopping already: the callback is not called again
    struct InCallback {
      bool& flag;
      explicit InCallback(bool& f) : flag(f) { flag = true; }
      ~InCallback() { flag = false; }
    } in_callback(in_callback_);
    try {
      progress_(p);
    } catch (py::error_already_set& e) {
      keep_and_stop(std::move(e));
      return;
    }
    poll();
  }

  void restore_threads() {
    if (threads_before_ > 0) omp_set_num_threads(threads_before_);
  }

  py::object progress_;
  int threads_before_;
  std::unique_ptr<Simulation> sim_;
  std::unique_ptr<py::error_already_set> pending_;
  bool finished_ = false;
  bool in_callback_ = false;  // the progress callback is running (on the thread of step() or finish())
};

}  // namespace

void bind_run(py::module_& m) {
  py::class_<RunProgress>(m, "Progress", "One status line of a run, as numbers (what the command line prints every 2 s): step, t, t_end, dt, "
                                      "rhs_evaluations, wall_seconds, eta_seconds (NaN until the run advanced), volume_drift "
                                      "(V/V0 - 1), steady_measure (NaN in the first time unit), health ('ok' or the active "
                                      "conditions).")
      .def_readonly("step", &RunProgress::step, "Accepted steps so far.")
      .def_readonly("t", &RunProgress::t, "Time reached.")
      .def_readonly("t_end", &RunProgress::t_end, "The scene's time.t_end.")
      .def_readonly("dt", &RunProgress::dt, "The last step.")
      .def_readonly("rhs_evaluations", &RunProgress::rhs_evaluations, "Right-hand-side evaluations (restarts included).")
      .def_readonly("wall_seconds", &RunProgress::wall_seconds, "Wall time of the run (restarts included).")
      .def_readonly("eta_seconds", &RunProgress::eta_seconds, "Estimated wall time to t_end (NaN at first).")
      .def_readonly("volume_drift", &RunProgress::volume_drift, "V/V0 - 1.")
      .def_readonly("steady_measure", &RunProgress::steady_measure, "The steady-state measure (NaN in the first time unit).")
      .def_readonly("health", &RunProgress::health, "The health monitors' status: 'ok' or the active conditions.")
      .def("__repr__", [](const RunProgress& p) {
        return "Progress(step=" + std::to_string(p.step) + ", t=" + py::repr(py::float_(p.t)).cast<std::string>() +
               ", t_end=" + py::repr(py::float_(p.t_end)).cast<std::string>() + ", health='" + p.health + "')";
      });

  py::class_<PySimulation>(m, "Simulation", "The driver's Simulation (use capsflow.Simulation, which checks arguments).")
      .def(py::init<const std::optional<Scene>&, std::string, bool, std::string, std::vector<std::string>, int, double,
                    py::object, std::string>(),
           py::arg("scene"), py::arg("output_dir"), py::arg("overwrite"), py::arg("restart"), py::arg("restart_overrides"),
           py::arg("threads"), py::arg("progress_interval"), py::arg("progress"), py::arg("command_line"),
           "Set up a run (new scene, or restart from a checkpoint): folder, mesh, right-hand side, first output.")
      .def("step", &PySimulation::step, "One accepted step; the stop reason once the run is over, else None.")
      .def("run_to_end", &PySimulation::run_to_end, "Steps until the run stops; the stop reason.")
      .def("finish", &PySimulation::finish, "Last output, checkpoint, summary.json; the exit code (0, 3 or 130).")
      .def("request_stop", &PySimulation::request_stop, "The next step stops the run as interrupted.")
      .def("raise_pending", &PySimulation::raise_pending, "Raise the exception that stopped the run, if any.")
      .def_property_readonly("has_pending", &PySimulation::has_pending, "An exception stopped the run and is not raised yet.")
      .def_property_readonly("finished", &PySimulation::finished, "finish() has run.")
      .def_property_readonly("stop_reason", &PySimulation::stop_reason, "summary.json's stop_reason, or None.")
      .def_property_readonly("t", [](PySimulation& s) { return s.sim().t(); }, "Time reached.")
      .def_property_readonly("dt", [](PySimulation& s) { return s.sim().dt(); }, "The last step.")
      .def_property_readonly("steps", [](PySimulation& s) { return s.sim().steps(); }, "Accepted steps (restarts included).")
      .def_property_readonly("rhs_evaluations", [](PySimulation& s) { return s.sim().rhs_evaluations(); },
                             "Right-hand-side evaluations (restarts included).")
      .def_property_readonly("folder", [](PySimulation& s) { return s.sim().folder().string(); }, "The output folder.")
      .def("positions", [](PySimulation& s) { return copy_points(s.sim().positions()); }, "Node positions (N, 3): a copy.")
      .def("load", [](PySimulation& s) { return copy_points(s.sim().load()); }, "The last evaluation's load q (N, 3): a copy.")
      .def(
          "velocity",
          [](PySimulation& s) {
            const Points* v = nullptr;
            {
              py::gil_scoped_release nogil;
              v = &s.sim().velocity();
            }
            return copy_points(*v);
          },
          "Node velocities (N, 3) at the current state: a copy.")
      .def(
          "reference_positions",
          [](py::object self) { return read_only_view(self.cast<PySimulation&>().sim().reference().vertices, self); },
          "The reference surface's nodes (N, 3): a read-only view.")
      .def(
          "triangles",
          [](py::object self) { return read_only_view(self.cast<PySimulation&>().sim().reference().triangles, self); },
          "The triangles (M, 3) int32: a read-only view.")
      .def(
          "health",
          [](PySimulation& s) {
            const HealthMonitor& h = s.sim().health();
            py::dict columns;
            for (const auto& [name, value] : h.columns()) columns[py::str(name)] = value;
            py::list active;
            for (const auto& [condition, name] : kHealthConditionNames)
              if (h.active(condition)) active.append(py::str(name));
            return py::dict(py::arg("status") = h.status(), py::arg("active") = active, py::arg("columns") = columns,
                            py::arg("summary") = h.summary().dump());
          },
          "The health monitors: status, active conditions, the timeseries columns of the last sample, the "
          "summary (JSON text).")
      .def(
          "write_checkpoint",
          [](PySimulation& s, const std::string& path) {
            py::gil_scoped_release nogil;
            s.sim().write_checkpoint(path);
          },
          py::arg("path"), "A checkpoint of the current state at path (a run restarts from it).");

  m.def(
      "set_log_level",
      [](const std::string& level) {
        const std::string before = spdlog::level::to_string_view(spdlog::get_level()).data();
        spdlog::set_level(spdlog::level::from_str(level));
        return before;
      },
      py::arg("level"), "Set the C++ log level ('info', 'warning', 'off', ...); returns the previous one.");
}

}  // namespace capsflow::python
