#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <memory>
#include <string>

#include "bindings.hpp"
#include "index_arrays.hpp"
#include "snakehead/tracking_fit.hpp"

namespace py = pybind11;

namespace snakehead::bindings {

namespace {

using Doubles = py::array_t<double, py::array::c_style | py::array::forcecast>;
using Indices = IndexArray;

void check_target(const TrackingFit& f, const Doubles& target, py::ssize_t samples, const char* what) {
  const bool one = samples < 0;
  const py::ssize_t dims = one ? 2 : 3;
  const py::ssize_t m = f.n_points();
  if (target.ndim() != dims || target.shape(dims - 2) != m || target.shape(dims - 1) != 3 ||
      (!one && target.shape(0) != samples))
    throw InputError(std::string(what) + " must have shape " + (one ? "" : "(S, ") + (one ? "(" : "") +
                     std::to_string(m) + ", 3)" + (one ? "" : " with S the rows of q"));
}

}  // namespace

void bind_tracking_fit(py::module_& m) {
  py::class_<TrackingFit, std::shared_ptr<TrackingFit>>(
      m, "TrackingFit",
      "The tracking interpolation's damped least-squares fit of the lifted joints to Eq. 41's points, with the "
      "ground, self-clearance and continuity terms (tracking_fit.hpp); immutable, safe to share between threads")
      .def(py::init([](const ChainModel& model, const ShapeSet& shapes, const Eigen::Matrix4d& origin,
                       const Indices& lift, const Indices& points, const Indices& lifted_links,
                       const Indices& self_pairs, double damping, int iterations, double step_tolerance,
                       double clearance, double ground_weight, double continuity, double self_clearance,
                       double self_step) {
             TrackingSpec spec;
             spec.lift = index_list<int>("lift", lift);
             spec.points = index_list<long>("points", points);
             spec.lifted_links = index_list<long>("lifted_links", lifted_links);
             spec.self_pairs = index_pairs("self_pairs", self_pairs);
             TrackingSettings s;
             s.damping = damping;
             s.iterations = iterations;
             s.step_tolerance = step_tolerance;
             s.clearance = clearance;
             s.ground_weight = ground_weight;
             s.continuity = continuity;
             s.self_clearance = self_clearance;
             s.self_step = self_step;
             return std::make_shared<TrackingFit>(model, shapes, origin, std::move(spec), s);
           }),
           py::arg("model"), py::arg("shapes"), py::arg("origin"), py::arg("lift"), py::arg("points"),
           py::arg("lifted_links"), py::arg("self_pairs"), py::kw_only(), py::arg("damping"), py::arg("iterations"),
           py::arg("step_tolerance"), py::arg("clearance"), py::arg("ground_weight"), py::arg("continuity"),
           py::arg("self_clearance"), py::arg("self_step"), py::keep_alive<1, 2>(), py::keep_alive<1, 3>(),
           "model: the chain; shapes: its links' shapes; origin: the chain base's world pose (4, 4); lift (k,): the "
           "fitted joints; points (m,): links whose origins track the targets; lifted_links: links kept `clearance` "
           "(m) above the ground; self_pairs (P, 2): shape pairs kept `self_clearance` (m) apart; the settings: "
           "python/snakehead/motion/cartesian.py's TRACKING_* constants")
      .def(
          "fit",
          [](const TrackingFit& f, const Doubles& q, const Doubles& targets) {
            if (q.ndim() != 2 || q.shape(1) != f.n_joints())
              throw InputError("q must have shape (S, " + std::to_string(f.n_joints()) + ")");
            check_target(f, targets, q.shape(0), "targets");
            py::array_t<double> out({q.shape(0), q.shape(1)});
            std::copy(q.data(), q.data() + q.size(), out.mutable_data());
            double* data = out.mutable_data();
            {
              py::gil_scoped_release release;
              f.fit(data, static_cast<long>(q.shape(0)), targets.data());
            }
            return out;
          },
          py::arg("q"), py::arg("targets"),
          "q (S, n) with rows 1 .. S-2's lifted joints fitted to targets (S, m, 3), each sample warm-started from "
          "the previous one's fit (row 0's lifted joints are the start); a new array")
      .def(
          "step",
          [](const TrackingFit& f, const Eigen::VectorXd& q, const Eigen::VectorXd& current, const Doubles& target) {
            check_target(f, target, -1, "target");
            TrackingStep s;
            {
              py::gil_scoped_release release;
              s = f.step(q, current, target.data());
            }
            return py::make_tuple(s.residual, s.jacobian, s.step);
          },
          py::arg("q"), py::arg("current"), py::arg("target"),
          "One damped least-squares step at q (n) towards target (m, 3) from the previous sample's lifted joints "
          "current (k): the stacked residual (rows,), its Jacobian (rows, k) and the step (k,), unclipped");
}

}  // namespace snakehead::bindings
