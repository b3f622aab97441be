// capsflow._core: the Stokeslet FMM and direct sum of capsflow::fmm on numpy arrays.
// Arguments arrive checked by capsflow/fmm.py (float64, C-contiguous, shapes, finite); the
// `noconvert` arguments make pybind11 refuse anything else instead of copying it, so C-contiguous
// float64 input is read in place. The GIL is released while C++ computes.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <atomic>
#include <cmath>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "bindings.hpp"
#include "capsflow/fmm/direct_sum.hpp"
#include "capsflow/fmm/fmm.hpp"
#include "capsflow/fmm/stokeslet.hpp"

namespace py = pybind11;

namespace capsflow::python {
namespace {

using Array = py::array_t<double, py::array::c_style>;
using StokesOperators = fmm::Operators<fmm::Stokeslet>;

// Rows of an (n, 3) array; the Python layer has checked the shape, this guards direct calls.
std::size_t rows3(const Array& a, const char* name) {
  if (a.ndim() != 2 || a.shape(1) != 3) throw py::value_error(std::string(name) + " must have shape (N, 3)");
  return static_cast<std::size_t>(a.shape(0));
}

// Flat index of the first NaN or infinity, -1 when all are finite (no temporary array).
long first_non_finite(const py::array_t<double, py::array::c_style>& a) {
  const double* p = a.data();
  const long n = static_cast<long>(a.size());
  for (long i = 0; i < n; ++i)
    if (!std::isfinite(p[i])) return i;
  return -1;
}

// The operators are the expensive part of building an FMM (computed once per order, then read
// from the disk cache). The last set used is kept, so repeated calls at one tolerance do not
// reload it, as a C++ caller that keeps its Fmm does not.
std::mutex g_operators_mutex;
std::shared_ptr<const StokesOperators> g_operators;

std::shared_ptr<const StokesOperators> operators_of_order(int order) {
  std::lock_guard<std::mutex> lock(g_operators_mutex);
  if (!g_operators || g_operators->order() != order) {
    g_operators.reset();  // free the old set before building the new one
    g_operators = std::make_shared<const StokesOperators>(order, "");
  }
  return g_operators;
}

void clear_operators() {
  std::lock_guard<std::mutex> lock(g_operators_mutex);
  g_operators.reset();
}

// One FMM over fixed points: set_points() builds the tree, evaluate() sums any number of force
// sets over it. A mutex serialises calls from several Python threads (the GIL is released).
class StokesletFmm {
 public:
  StokesletFmm(double tolerance, int order, int leaf_size, int threads) {
    opt_.tolerance = tolerance;
    opt_.order = order;
    opt_.leaf_size = leaf_size;
    opt_.threads = threads;
    const int p = order > 0 ? order : fmm::order_for_tolerance(tolerance);
    fmm_ = std::make_unique<fmm::Fmm<fmm::Stokeslet>>(opt_, operators_of_order(p));
  }

  void set_points(const Array& sources, const std::optional<Array>& targets) {
    const std::size_t ns = rows3(sources, "sources");
    const Array& trg = targets ? *targets : sources;
    const std::size_t nt = rows3(trg, "targets");
    py::gil_scoped_release nogil;  // before the lock: a thread waiting for it must not hold the GIL
    std::lock_guard<std::mutex> lock(mutex_);
    n_src_ = ns;
    n_trg_ = nt;
    fmm_->setup(sources.data(), ns, trg.data(), nt);
  }

  // forces (n_src, 3) → velocities (n_trg, 3); (k, n_src, 3) → (k, n_trg, 3) in one pass.
  Array evaluate(const Array& forces) {
    const std::size_t ns = n_src_, nt = n_trg_;
    const bool stacked = forces.ndim() == 3;
    if (!(forces.ndim() == 2 || stacked) || forces.shape(forces.ndim() - 1) != 3 ||
        static_cast<std::size_t>(forces.shape(forces.ndim() - 2)) != ns)
      throw py::value_error("forces must have shape (n_sources, 3) or (k, n_sources, 3)");
    const py::ssize_t k = stacked ? forces.shape(0) : 1;
    Array out = stacked ? Array({k, static_cast<py::ssize_t>(nt), py::ssize_t{3}})
                        : Array({static_cast<py::ssize_t>(nt), py::ssize_t{3}});
    double* u = out.mutable_data();
    py::gil_scoped_release nogil;  // before the lock: a thread waiting for it must not hold the GIL
    std::lock_guard<std::mutex> lock(mutex_);
    if (n_src_ != ns || n_trg_ != nt) throw std::runtime_error("the points were changed by another thread during evaluate");
    fmm_->evaluate(forces.data(), u, static_cast<int>(k));
    return out;
  }

  int order() const { return fmm_->order(); }
  int leaf_size() const { return fmm_->leaf_size(); }
  int threads() const { return fmm_->threads(); }
  std::size_t n_sources() const { return n_src_; }
  std::size_t n_targets() const { return n_trg_; }
  py::dict timings() const {
    const fmm::FmmTimings& t = fmm_->timings();
    py::dict d;
    d["setup"] = t.setup_total;
    d["evaluate"] = t.eval_total;
    d["p2m"] = t.p2m;
    d["m2m"] = t.m2m;
    d["m2l"] = t.m2l;
    d["x_list"] = t.x_list;
    d["l2l"] = t.l2l;
    d["p2p"] = t.p2p;
    d["l2p"] = t.l2p;
    d["other"] = t.other;
    return d;
  }

 private:
  fmm::FmmOptions opt_;
  std::unique_ptr<fmm::Fmm<fmm::Stokeslet>> fmm_;
  std::atomic<std::size_t> n_src_{0}, n_trg_{0};  // read without the lock to size the output
  std::mutex mutex_;
};

Array stokeslet_direct(const Array& sources, const Array& forces, const std::optional<Array>& targets, int threads) {
  const std::size_t ns = rows3(sources, "sources");
  if (rows3(forces, "forces") != ns) throw py::value_error("forces must have as many rows as sources");
  const Array& trg = targets ? *targets : sources;
  const std::size_t nt = rows3(trg, "targets");
  Array out({static_cast<py::ssize_t>(nt), py::ssize_t{3}});
  double* u = out.mutable_data();
  py::gil_scoped_release nogil;
  fmm::direct_sum<fmm::Stokeslet>(sources.data(), ns, forces.data(), trg.data(), nt, u, threads);
  return out;
}

}  // namespace

void bind_fmm(py::module_& m) {
  m.def("first_non_finite", &first_non_finite, py::arg("array").noconvert(),
        "Flat index of the first NaN or infinity in a C-contiguous float64 array, -1 if none.");
  m.def("fmm_order_for_tolerance", &fmm::order_for_tolerance, py::arg("tolerance"),
        "The FMM order p the calibration table (fmm/calibration.hpp) gives for a relative L2 tolerance.");
  m.def("clear_fmm_operators", &clear_operators, "Free the FMM operators kept in memory since the last call.");
  m.def("stokeslet_direct", &stokeslet_direct, py::arg("sources").noconvert(), py::arg("forces").noconvert(),
        py::arg("targets").noconvert() = py::none(), py::arg("threads") = 0,
        "Direct Stokeslet sum (checked arguments: see capsflow.fmm.stokeslet_direct).");
  py::class_<StokesletFmm>(m, "StokesletFmm", "Stokeslet FMM over fixed points (see capsflow.fmm.StokesletFmm).")
      .def(py::init([](double tolerance, int order, int leaf_size, int threads) {
             py::gil_scoped_release nogil;  // the operators may be built or read from disk
             return std::make_unique<StokesletFmm>(tolerance, order, leaf_size, threads);
           }),
           py::arg("tolerance"), py::arg("order"), py::arg("leaf_size"), py::arg("threads"))
      .def("set_points", &StokesletFmm::set_points, py::arg("sources").noconvert(),
           py::arg("targets").noconvert() = py::none())
      .def("evaluate", &StokesletFmm::evaluate, py::arg("forces").noconvert())
      .def_property_readonly("order", &StokesletFmm::order)
      .def_property_readonly("leaf_size", &StokesletFmm::leaf_size)
      .def_property_readonly("threads", &StokesletFmm::threads)
      .def_property_readonly("n_sources", &StokesletFmm::n_sources)
      .def_property_readonly("n_targets", &StokesletFmm::n_targets)
      .def_property_readonly("timings", &StokesletFmm::timings);
}

}  // namespace capsflow::python
