#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "snakehead/model.hpp"
#include "snakehead/support.hpp"

namespace py = pybind11;

namespace snakehead::bindings {

void bind_support(py::module_& m) {
  m.def("convex_hull_2d", &convex_hull, py::arg("points"),
        "Counter-clockwise convex hull indices of (N, 2) points; edge points left out");
  m.def(
      "hull_margins",
      [](py::array_t<double, py::array::c_style | py::array::forcecast> points,
         py::array_t<bool, py::array::c_style | py::array::forcecast> active,
         py::array_t<double, py::array::c_style | py::array::forcecast> xy) {
        if (points.ndim() != 3 || points.shape(2) != 2) throw InputError("points must have shape (T, N, 2)");
        const long T = static_cast<long>(points.shape(0)), N = static_cast<long>(points.shape(1));
        if (active.ndim() != 2 || active.shape(0) != T || active.shape(1) != N)
          throw InputError("active must have shape (T, N) like points");
        if (xy.ndim() != 2 || xy.shape(0) != T || xy.shape(1) != 2) throw InputError("xy must have shape (T, 2)");
        std::vector<double> out;
        {
          py::gil_scoped_release release;
          out = hull_margins(points.data(), reinterpret_cast<const unsigned char*>(active.data()), xy.data(), T, N);
        }
        py::array_t<double> a(static_cast<py::ssize_t>(out.size()));
        std::copy(out.begin(), out.end(), a.mutable_data());
        return a;
      },
      py::arg("points"), py::arg("active"), py::arg("xy"),
      "Signed distance (> 0 inside) of each sample's xy to the convex hull of its active points: (T,)");
  m.def(
      "convex_hulls",
      [](py::array_t<double, py::array::c_style | py::array::forcecast> points,
         py::array_t<bool, py::array::c_style | py::array::forcecast> active) {
        if (points.ndim() != 3 || points.shape(2) != 2) throw InputError("points must have shape (T, N, 2)");
        const long T = static_cast<long>(points.shape(0)), N = static_cast<long>(points.shape(1));
        if (active.ndim() != 2 || active.shape(0) != T || active.shape(1) != N)
          throw InputError("active must have shape (T, N) like points");
        py::array_t<int> vertex({static_cast<py::ssize_t>(T), static_cast<py::ssize_t>(N)});
        py::array_t<int> count(static_cast<py::ssize_t>(T));
        int* v = vertex.mutable_data();
        int* c = count.mutable_data();
        {
          py::gil_scoped_release release;
          convex_hulls(points.data(), reinterpret_cast<const unsigned char*>(active.data()), T, N, v, c);
        }
        return py::make_tuple(vertex, count);
      },
      py::arg("points"), py::arg("active"),
      "Each sample's counter-clockwise convex hull of its active points: vertex indices (T, N), -1 after the "
      "count, and the counts (T,)");
}

}  // namespace snakehead::bindings
