#include <pybind11/numpy.h>

#include <string>

#include "bindings.hpp"
#include "snakehead/model.hpp"
#include "snakehead/piecewise_polynomial.hpp"

namespace py = pybind11;

namespace snakehead::bindings {

void bind_piecewise_polynomial(py::module_& m) {
  using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;
  m.def(
      "evaluate_piecewise_polynomial",
      [](Array c, Array breaks, Array points) {
        if (c.ndim() != 3) throw InputError("c must have shape (k, m, n)");
        if (breaks.ndim() != 1 || breaks.shape(0) != c.shape(1) + 1)
          throw InputError("breaks must have shape (" + std::to_string(c.shape(1) + 1) + ",) for " +
                           std::to_string(c.shape(1)) + " intervals");
        if (points.ndim() != 1) throw InputError("points must have shape (N,)");
        const long k = static_cast<long>(c.shape(0)), intervals = static_cast<long>(c.shape(1));
        const long n = static_cast<long>(c.shape(2)), N = static_cast<long>(points.shape(0));
        py::array_t<double> out({static_cast<py::ssize_t>(N), static_cast<py::ssize_t>(n)});
        const double *cp = c.data(), *bp = breaks.data(), *pp = points.data();
        double* op = out.mutable_data();
        {
          py::gil_scoped_release release;
          evaluate_piecewise_polynomial(cp, k, intervals, n, bp, pp, N, op);
        }
        return out;
      },
      py::arg("c"), py::arg("breaks"), py::arg("points"),
      "A piecewise polynomial's values at points (N,) -> (N, n), bit for bit what scipy.interpolate.PPoly(c, breaks) "
      "gives (nu = 0, extrapolating): c (k, m, n) highest power first, breaks (m + 1,) strictly increasing.");
}

}  // namespace snakehead::bindings
