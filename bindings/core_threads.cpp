#include "bindings.hpp"
#include "snakehead/core_threads.hpp"

namespace py = pybind11;

namespace snakehead::bindings {

void bind_core_threads(py::module_& m) {
  m.def("core_threads", &core_threads,
        "The threads the core's batch work (TRAC-IK batches, a workspace sweep without a thread count) may use in "
        "this process: the value set, else SNAKEHEAD_NUM_THREADS, else OMP_NUM_THREADS, else every hardware thread.");
  m.def("set_core_threads", &set_core_threads, py::arg("n"),
        "Sets core_threads() for this process (1..MAX_THREADS; 0 restores the default); InputError otherwise.");
}

}  // namespace snakehead::bindings
