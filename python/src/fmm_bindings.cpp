// capsflow._core: the Stokeslet and stresslet (double-layer) FMMs and direct sums of capsflow::fmm on
// numpy arrays. One template over the kernel serves both: a kernel of 3·P density components per
// source takes P arrays of shape (…, N, 3) (the Stokeslet: forces; the stresslet: forces, normals).
// Arguments arrive checked by capsflow/fmm.py (float64, C-contiguous, shapes, finite); the
// `noconvert` arguments make pybind11 refuse anything else instead of copying it, so C-contiguous
// float64 input is read in place. The GIL is released while C++ computes. One array (P = 1) is passed
// to the kernel as it is; several are interleaved into one C++ buffer of rows f0 f1 f2 n0 n1 n2, the
// layout fmm::Stresslet reads (the only copy: the kernel needs the components of a source together).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <atomic>
#include <cmath>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "capsflow/core/driver/thread_count.hpp"
#include "capsflow/fmm/direct_sum.hpp"
#include "capsflow/fmm/fmm.hpp"
#include "capsflow/fmm/stokeslet.hpp"
#include "capsflow/fmm/stresslet.hpp"

namespace py = pybind11;

namespace capsflow::python {
namespace {

using Array = py::array_t<double, py::array::c_style>;

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

// The density arrays of one call: P arrays of 3 components per source, the kernel's 3·P.
template <class Kernel>
constexpr std::size_t kParts = static_cast<std::size_t>(Kernel::src_dim / 3);
template <class Kernel>
using Parts = std::array<const Array*, kParts<Kernel>>;
template <class Kernel>
constexpr const char* kPartNames = "forces";
template <>
constexpr const char* kPartNames<fmm::Stresslet> = "forces and normals";

// Checks that every part has shape (n_src, 3) or, when `stacked`, (k, n_src, 3) with one k; returns k.
template <class Kernel>
py::ssize_t stack_size(const Parts<Kernel>& parts, std::size_t n_src, bool stacked) {
  static_assert(Kernel::src_dim % 3 == 0, "densities are passed as arrays of 3-vectors");
  const Array& a0 = *parts[0];
  for (const Array* a : parts) {
    const bool ok_ndim = a->ndim() == 2 || (stacked && a->ndim() == 3);
    if (!ok_ndim || a->shape(a->ndim() - 1) != 3 || static_cast<std::size_t>(a->shape(a->ndim() - 2)) != n_src ||
        a->ndim() != a0.ndim() || (a->ndim() == 3 && a->shape(0) != a0.shape(0)))
      throw py::value_error(std::string(kPartNames<Kernel>) + " must have one shape, (n_sources, 3)" +
                            (stacked ? " or (k, n_sources, 3)" : ""));
  }
  return a0.ndim() == 3 ? a0.shape(0) : 1;
}

// The densities as the kernel reads them, rows of 3·P: one array is read in place; P > 1 arrays are
// interleaved into one buffer (part after part within a row: f0 f1 f2 n0 n1 n2 for the stresslet).
// Needs no GIL: it reads only the arrays' memory.
template <class Kernel>
class Packed {
 public:
  Packed(const Parts<Kernel>& parts, std::size_t rows) {
    constexpr std::size_t P = kParts<Kernel>;
    if constexpr (P == 1) {
      data_ = parts[0]->data();
    } else {
      buffer_.resize(rows * 3 * P);
      for (std::size_t p = 0; p < P; ++p) {
        const double* in = parts[p]->data();
        for (std::size_t r = 0; r < rows; ++r)
          for (std::size_t c = 0; c < 3; ++c) buffer_[(r * P + p) * 3 + c] = in[r * 3 + c];
      }
      data_ = buffer_.data();
    }
  }
  const double* data() const { return data_; }

 private:
  std::vector<double> buffer_;
  const double* data_ = nullptr;
};

// The operators are the expensive part of building an FMM (computed once per order, then read
// from the disk cache). The last set used per kernel is kept, so repeated calls at one tolerance
// do not reload it, as a C++ caller that keeps its Fmm does not.
template <class Kernel>
struct OperatorCache {
  inline static std::mutex mutex;
  inline static std::shared_ptr<const fmm::Operators<Kernel>> operators;

  static std::shared_ptr<const fmm::Operators<Kernel>> of_order(int order) {
    std::lock_guard<std::mutex> lock(mutex);
    if (!operators || operators->order() != order) {
      operators.reset();  // free the old set before building the new one
      operators = std::make_shared<const fmm::Operators<Kernel>>(order, "");
    }
    return operators;
  }
  static void clear() {
    std::lock_guard<std::mutex> lock(mutex);
    operators.reset();
  }
};

void clear_operators() {
  OperatorCache<fmm::Stokeslet>::clear();
  OperatorCache<fmm::Stresslet>::clear();
}

int order_for_tolerance(double tolerance, const std::string& kernel) {
  if (kernel == fmm::Stokeslet::name) return fmm::order_for_tolerance<fmm::Stokeslet>(tolerance);
  if (kernel == fmm::Stresslet::name) return fmm::order_for_tolerance<fmm::Stresslet>(tolerance);
  throw py::value_error("kernel must be 'stokeslet' or 'stresslet', got '" + kernel + "'");
}

// One FMM over fixed points: set_points() builds the tree, evaluate() sums any number of density
// sets over it. A mutex serialises calls from several Python threads (the GIL is released).
template <class Kernel>
class KernelFmm {
 public:
  KernelFmm(double tolerance, int order, int leaf_size, int threads) {
    check_thread_count(threads, "threads = " + std::to_string(threads));  // libgomp would end the interpreter
    opt_.tolerance = tolerance;
    opt_.order = order;
    opt_.leaf_size = leaf_size;
    opt_.threads = threads;
    const int p = order > 0 ? order : fmm::order_for_tolerance<Kernel>(tolerance);
    fmm_ = std::make_unique<fmm::Fmm<Kernel>>(opt_, OperatorCache<Kernel>::of_order(p));
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

  // densities (n_src, 3) each → velocities (n_trg, 3); (k, n_src, 3) each → (k, n_trg, 3) in one pass.
  Array evaluate(const Parts<Kernel>& parts) {
    const std::size_t ns = n_src_, nt = n_trg_;
    const py::ssize_t k = stack_size<Kernel>(parts, ns, true);
    const bool stacked = parts[0]->ndim() == 3;
    Array out = stacked ? Array({k, static_cast<py::ssize_t>(nt), py::ssize_t{3}})
                        : Array({static_cast<py::ssize_t>(nt), py::ssize_t{3}});
    double* u = out.mutable_data();
    py::gil_scoped_release nogil;  // before the lock: a thread waiting for it must not hold the GIL
    std::lock_guard<std::mutex> lock(mutex_);
    if (n_src_ != ns || n_trg_ != nt) throw std::runtime_error("the points were changed by another thread during evaluate");
    const Packed<Kernel> density(parts, static_cast<std::size_t>(k) * ns);
    fmm_->evaluate(density.data(), u, static_cast<int>(k));
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
  std::unique_ptr<fmm::Fmm<Kernel>> fmm_;
  std::atomic<std::size_t> n_src_{0}, n_trg_{0};  // read without the lock to size the output
  std::mutex mutex_;
};

template <class Kernel>
Array direct(const Array& sources, const Parts<Kernel>& parts, const std::optional<Array>& targets, int threads) {
  check_thread_count(threads, "threads = " + std::to_string(threads));  // libgomp would end the interpreter
  const std::size_t ns = rows3(sources, "sources");
  stack_size<Kernel>(parts, ns, false);
  const Array& trg = targets ? *targets : sources;
  const std::size_t nt = rows3(trg, "targets");
  Array out({static_cast<py::ssize_t>(nt), py::ssize_t{3}});
  double* u = out.mutable_data();
  py::gil_scoped_release nogil;
  const Packed<Kernel> density(parts, ns);
  fmm::direct_sum<Kernel>(sources.data(), ns, density.data(), trg.data(), nt, u, threads);
  return out;
}

// The direct sum `direct_name` and the class `class_name` of one kernel. `direct_fn` and `evaluate_fn`
// take the kernel's density arrays as separate arguments, named by `density_args` (noconvert).
template <class Kernel, class DirectFn, class EvaluateFn, class... DensityArgs>
void bind_kernel(py::module_& m, const char* direct_name, const char* direct_doc, const char* class_name,
                 const char* class_doc, DirectFn direct_fn, EvaluateFn evaluate_fn, DensityArgs... density_args) {
  using Obj = KernelFmm<Kernel>;
  m.def(direct_name, direct_fn, py::arg("sources").noconvert(), density_args...,
        py::arg("targets").noconvert() = py::none(), py::arg("threads") = 0, direct_doc);
  py::class_<Obj>(m, class_name, class_doc)
      .def(py::init([](double tolerance, int order, int leaf_size, int threads) {
             py::gil_scoped_release nogil;  // the operators may be built or read from disk
             return std::make_unique<Obj>(tolerance, order, leaf_size, threads);
           }),
           py::arg("tolerance"), py::arg("order"), py::arg("leaf_size"), py::arg("threads"))
      .def("set_points", &Obj::set_points, py::arg("sources").noconvert(), py::arg("targets").noconvert() = py::none())
      .def("evaluate", evaluate_fn, density_args...)
      .def_property_readonly("order", &Obj::order)
      .def_property_readonly("leaf_size", &Obj::leaf_size)
      .def_property_readonly("threads", &Obj::threads)
      .def_property_readonly("n_sources", &Obj::n_sources)
      .def_property_readonly("n_targets", &Obj::n_targets)
      .def_property_readonly("timings", &Obj::timings);
}

}  // namespace

void bind_fmm(py::module_& m) {
  using fmm::Stokeslet;
  using fmm::Stresslet;
  using Opt = const std::optional<Array>&;
  m.def("first_non_finite", &first_non_finite, py::arg("array").noconvert(),
        "Flat index of the first NaN or infinity in a C-contiguous float64 array, -1 if none.");
  m.def("fmm_order_for_tolerance", &order_for_tolerance, py::arg("tolerance"), py::arg("kernel") = "stokeslet",
        "The FMM order p the calibration table of a kernel (fmm/calibration.hpp) gives for a relative L2 tolerance.");
  m.def("clear_fmm_operators", &clear_operators, "Free the FMM operators kept in memory since the last call.");
  bind_kernel<Stokeslet>(
      m, "stokeslet_direct", "Direct Stokeslet sum (checked arguments: see capsflow.fmm.stokeslet_direct).",
      "StokesletFmm", "Stokeslet FMM over fixed points (see capsflow.fmm.StokesletFmm).",
      [](const Array& s, const Array& f, Opt t, int threads) { return direct<Stokeslet>(s, {&f}, t, threads); },
      [](KernelFmm<Stokeslet>& o, const Array& f) { return o.evaluate({&f}); }, py::arg("forces").noconvert());
  bind_kernel<Stresslet>(
      m, "stresslet_direct", "Direct stresslet sum (checked arguments: see capsflow.fmm.stresslet_direct).",
      "StressletFmm", "Stresslet (double-layer) FMM over fixed points (see capsflow.fmm.StressletFmm).",
      [](const Array& s, const Array& f, const Array& n, Opt t, int threads) {
        return direct<Stresslet>(s, {&f, &n}, t, threads);
      },
      [](KernelFmm<Stresslet>& o, const Array& f, const Array& n) { return o.evaluate({&f, &n}); },
      py::arg("forces").noconvert(), py::arg("normals").noconvert());
}

}  // namespace capsflow::python
