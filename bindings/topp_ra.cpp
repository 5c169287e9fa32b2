#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "snakehead/model.hpp"
#include "snakehead/topp_ra.hpp"

namespace py = pybind11;

namespace snakehead::bindings {

namespace {
using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;
using MatrixView = Eigen::Map<const RowMatrixXd>;

// A 2-D array as a row-major matrix (no copy); cols < 0: any number of columns.
MatrixView matrix(const Array& a, py::ssize_t cols, const char* what) {
  if (a.ndim() != 2 || (cols >= 0 && a.shape(1) != cols)) throw InputError(std::string(what) + " has the wrong shape");
  return MatrixView(a.data(), a.shape(0), a.shape(1));
}

const char* status_name(ToppRaStatus status) {
  switch (status) {
    case ToppRaStatus::kFeasible:
      return "feasible";
    case ToppRaStatus::kUncontrollable:
      return "uncontrollable";
    case ToppRaStatus::kStartOutside:
      return "start_outside";
    case ToppRaStatus::kForwardFailed:
      return "forward_failed";
  }
  return "unknown";
}
}  // namespace

void bind_topp_ra(py::module_& m) {
  py::class_<ToppRaResult>(m, "ToppRaResult", "The result of topp_ra")
      .def_property_readonly(
          "status", [](const ToppRaResult& r) { return status_name(r.status); },
          "'feasible', 'uncontrollable' (the backward pass found an empty controllable set), 'start_outside' "
          "(x_start is not in K_0) or 'forward_failed' (round-off: the forward pass found no u)")
      .def_readonly("failed_at", &ToppRaResult::failed_at, "the gridpoint where it failed; -1 when feasible")
      .def_property_readonly(
          "x", [](const ToppRaResult& r) { return py::array_t<double>(r.x.size(), r.x.data()); },
          "(N+1,) squared path speeds (NaN where the forward pass did not reach)")
      .def_property_readonly(
          "u", [](const ToppRaResult& r) { return py::array_t<double>(r.u.size(), r.u.data()); },
          "(N,) path accelerations of the stages, (x_{i+1} - x_i) / (2 delta_i)")
      .def_property_readonly(
          "K", [](const ToppRaResult& r) -> RowMatrixX2d { return r.K; },
          "(N+1, 2) controllable sets of x (NaN at failed_at and before when uncontrollable)")
      .def_readonly("lp_count", &ToppRaResult::lp_count, "LPs solved");
  m.def(
      "topp_ra",
      [](Array grid, Array A, Array B, Array C, Array u_bounds, Array x_bounds, double x_start, double x_end) {
        if (grid.ndim() != 1) throw InputError("grid must be one-dimensional (N+1,)");
        const Eigen::Map<const Eigen::VectorXd> s(grid.data(), grid.shape(0));
        const auto a = matrix(A, -1, "A (N, m)"), b = matrix(B, -1, "B (N, m)"), c = matrix(C, -1, "C (N, m)");
        const auto ub = matrix(u_bounds, 2, "u_bounds (N, 2)"), xb = matrix(x_bounds, 2, "x_bounds (N+1, 2)");
        py::gil_scoped_release release;
        return topp_ra(s, a, b, c, ub, xb, x_start, x_end);
      },
      py::arg("grid"), py::arg("A"), py::arg("B"), py::arg("C"), py::arg("u_bounds"), py::arg("x_bounds"),
      py::arg("x_start") = 0.0, py::arg("x_end") = 0.0,
      "TOPP-RA over grid (N+1,) with stage rows A u + B x <= C (N, m each), u_bounds (N, 2), x_bounds (N+1, 2): "
      "the controllable sets and the greedy forward pass from x_start to x_end (include/snakehead/topp_ra.hpp)");
  m.def(
      "topp_ra_canonical",
      [](Array grid, Array P, Array Q, Array R, Array x_max, double x_start, double x_end) {
        if (grid.ndim() != 1) throw InputError("grid must be one-dimensional (N+1,)");
        if (x_max.ndim() != 1) throw InputError("x_max must be one-dimensional (N+1,)");
        const Eigen::Map<const Eigen::VectorXd> s(grid.data(), grid.shape(0)), xm(x_max.data(), x_max.shape(0));
        const auto p = matrix(P, -1, "P (N+1, m)"), q = matrix(Q, -1, "Q (N+1, m)"), r = matrix(R, -1, "R (N+1, m)");
        py::gil_scoped_release release;
        return topp_ra_canonical(s, p, q, r, xm, x_start, x_end);
      },
      py::arg("grid"), py::arg("P"), py::arg("Q"), py::arg("R"), py::arg("x_max"), py::arg("x_start") = 0.0,
      py::arg("x_end") = 0.0,
      "TOPP-RA over grid (N+1,) with the gridpoints' rows P u + Q x <= R (N+1, m each) and x <= x_max (N+1,), "
      "discretized as toppra's interpolation discretization in the core: topp_ra's result for the stage rows "
      "retiming._topp.interpolated makes, to the bit (include/snakehead/topp_ra.hpp)");
  m.def(
      "solve_lp2d",
      [](double v_u, double v_x, Array rows_array, const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) {
        const auto rows = matrix(rows_array, 3, "rows (m, 3): a, b, c of a u + b x <= c");
        if (!rows.allFinite() || lo.hasNaN() || hi.hasNaN()) throw InputError("rows, lo and hi must not be NaN");
        std::vector<HalfPlane> h(rows.rows());
        for (Eigen::Index k = 0; k < rows.rows(); ++k) h[k] = normalized({rows(k, 0), rows(k, 1), rows(k, 2)});
        const Lp2dSolution s = solve_lp2d(v_u, v_x, h.data(), static_cast<int>(h.size()), lo.data(), hi.data());
        return py::make_tuple(s.feasible, s.u, s.x);
      },
      py::arg("v_u"), py::arg("v_x"), py::arg("rows"), py::arg("lo"), py::arg("hi"),
      "max v_u u + v_x x subject to rows (m, 3) a u + b x <= c and lo <= (u, x) <= hi: (feasible, u, x)");
}

}  // namespace snakehead::bindings
