#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <optional>

#include "bindings.hpp"
#include "snakehead/neck_fit.hpp"

namespace py = pybind11;

namespace snakehead::bindings {

void bind_neck_fit(py::module_& m) {
  m.def(
      "fit_neck",
      [](const ChainModel& neck, const Eigen::Matrix4d& P0_frame, const Eigen::Vector3d& P_d,
         const Eigen::Vector3d& r_d, std::optional<Eigen::VectorXd> q_init, double h, int grid_points,
         double grid_fraction, int iterations, double tolerance, double continuity_tolerance) {
        if (!P0_frame.allFinite() || P0_frame.row(3) != Eigen::RowVector4d(0.0, 0.0, 0.0, 1.0))
          throw InputError("fit_neck: P0_frame must be a finite rigid frame (last row 0 0 0 1)");
        NeckFitSettings s;
        s.h = h;
        s.grid_points = grid_points;
        s.grid_fraction = grid_fraction;
        s.iterations = iterations;
        s.tolerance = tolerance;
        s.continuity_tolerance = continuity_tolerance;
        NeckFit fit;
        {
          py::gil_scoped_release release;
          fit = fit_neck(neck, Eigen::Isometry3d(P0_frame), P_d, r_d, s, q_init ? &*q_init : nullptr);
        }
        return py::make_tuple(fit.q, fit.cost);
      },
      py::arg("neck"), py::arg("P0_frame"), py::arg("P_d"), py::arg("r_d"), py::arg("q_init"), py::kw_only(),
      py::arg("h"), py::arg("grid_points"), py::arg("grid_fraction"), py::arg("iterations"), py::arg("tolerance"),
      py::arg("continuity_tolerance"),
      "Eq. 22 (neck_fit.hpp): the neck joints minimising |P_a - P_d|^2 + h |r_d x r_a|^2 within their limits, by a "
      "bounded Levenberg-Marquardt from q_init (None: none) and from the best point of a grid; (q, cost)");
}

}  // namespace snakehead::bindings
