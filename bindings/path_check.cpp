#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <functional>
#include <optional>
#include <string>

#include "bindings.hpp"
#include "index_arrays.hpp"
#include "sample_arrays.hpp"
#include "snakehead/path_check.hpp"

namespace py = pybind11;

namespace snakehead::bindings {

namespace {

using Doubles = SampleArray;
using Indices = IndexArray;

// What a proof evaluated (PathVerdict's and MotionVerdict's counts and smallest values) into d.
template <class Verdict>
void put_counts(py::dict& d, const Verdict& v) {
  d["samples"] = v.samples;
  d["proven"] = v.proven;
  d["unproven"] = v.unproven;
  d["violations"] = v.violations;
  d["ground"] = v.ground;
  d["self"] = v.self;
  d["obstacle"] = v.obstacle;
}

}  // namespace

void bind_path_check(py::module_& m) {
  py::class_<PathChecker, std::shared_ptr<PathChecker>>(
      m, "PathChecker",
      "Ground, self and obstacle clearances of a chain's configurations, per sample and proven along straight "
      "joint segments (path_check.hpp); immutable, safe to share between threads")
      .def(py::init([](const ChainModel& model, const ShapeSet& shapes, const Eigen::Matrix4d& origin,
                       const Indices& ground_shapes, const Indices& self_pairs,
                       std::optional<std::reference_wrapper<const ShapeSet>> obstacles,
                       const Indices& obstacle_pairs, double ground_floor, double obstacle_cutoff) {
             PathCheckSpec spec;
             spec.ground_shapes = index_list("ground_shapes", ground_shapes);
             spec.self_pairs = index_pairs("self_pairs", self_pairs);
             spec.obstacle_pairs = index_pairs("obstacle_pairs", obstacle_pairs);
             spec.ground_floor = ground_floor;
             spec.obstacle_cutoff = obstacle_cutoff;
             return std::make_shared<PathChecker>(model, shapes, origin, std::move(spec),
                                                 obstacles ? &obstacles->get() : nullptr);
           }),
           py::arg("model"), py::arg("shapes"), py::arg("origin"), py::arg("ground_shapes"), py::arg("self_pairs"),
           py::arg("obstacles"), py::arg("obstacle_pairs"), py::arg("ground_floor"), py::arg("obstacle_cutoff"),
           py::keep_alive<1, 2>(), py::keep_alive<1, 3>(), py::keep_alive<1, 7>(),
           "model: the chain; shapes: its links' shapes; origin: the chain base's world pose (4, 4); ground_shapes "
           "(k,): shapes whose lowest point must stay >= ground_floor (m); self_pairs (P, 2): shape pairs that must "
           "stay apart; obstacles: a ShapeSet on one world frame (or None) and obstacle_pairs (Q, 2) (robot shape, "
           "obstacle shape); obstacle_cutoff (m): per-sample obstacle distances are exact below it")
      .def(
          "sample",
          [](const PathChecker& c, const Doubles& qs) {
            const long T = samples_of("qs", qs, c.n_joints());
            SampleClearances s;
            {
              py::gil_scoped_release release;
              s = c.sample(qs.data(), T);
            }
            const std::vector<py::ssize_t> shape{static_cast<py::ssize_t>(T)};
            return py::make_tuple(array_of(s.ground, shape), array_of(s.self, shape), array_of(s.obstacle, shape));
          },
          py::arg("qs"),
          "Each configuration's (T, n) smallest ground clearance, self clearance and obstacle distance (m): three "
          "(T,) arrays, +inf where nothing is checked")
      .def(
          "motion_bounds",
          [](const PathChecker& c, const Eigen::VectorXd& qa, const Eigen::VectorXd& qb) {
            if (qa.size() != c.n_joints() || qb.size() != c.n_joints())
              throw InputError("motion_bounds: qa and qb must have n_joints entries");
            std::vector<double> B, Z;
            {
              py::gil_scoped_release release;
              c.motion_bounds(qa, qb, B, Z);
            }
            const std::vector<py::ssize_t> shape{static_cast<py::ssize_t>(B.size())};
            return py::make_tuple(array_of(B, shape), array_of(Z, shape));
          },
          py::arg("qa"), py::arg("qb"),
          "Per robot shape: how far any of its points moves (m) and how far its lowest z changes (m) along the "
          "straight joint segment qa -> qb (proven bounds: path_check.hpp)")
      .def(
          "check_path",
          [](const PathChecker& c, const Doubles& waypoints, double first_step, double floor_step,
             bool stop_at_violation) {
            const long K = samples_of("waypoints", waypoints, c.n_joints());
            PathOptions o;
            o.first_step = first_step;
            o.floor_step = floor_step;
            o.stop_at_violation = stop_at_violation;
            PathVerdict v;
            {
              py::gil_scoped_release release;
              v = c.check_path(waypoints.data(), K, o);
            }
            py::array_t<bool> segments(static_cast<py::ssize_t>(v.segment_clear.size()));
            for (std::size_t i = 0; i < v.segment_clear.size(); ++i) segments.mutable_at(i) = v.segment_clear[i] != 0;
            py::dict d;
            d["clear"] = v.clear() && v.violations == 0;
            d["segments"] = segments;
            put_counts(d, v);
            return d;
          },
          py::arg("waypoints"), py::arg("first_step") = 0.05, py::arg("floor_step") = 1e-3,
          py::arg("stop_at_violation") = true,
          "Proves the straight joint segments between waypoints (K, n) clear: a dict with clear, segments (K-1,) "
          "bool, samples evaluated, intervals proven / unproven (at the floor), violations (samples below a floor) "
          "and the smallest ground, self, obstacle values evaluated")
      .def(
          "check_motion",
          [](const PathChecker& c, const Doubles& qs, double first_step, double floor_step) {
            const long T = samples_of("qs", qs, c.n_joints());
            PathOptions o;
            o.first_step = first_step;
            o.floor_step = floor_step;
            MotionVerdict v;
            {
              py::gil_scoped_release release;
              v = c.check_motion(qs.data(), T, o);
            }
            py::dict d;
            d["clear"] = v.clear();
            put_counts(d, v);
            d["obstacle_lower"] = array_of(v.obstacle_lower, {static_cast<py::ssize_t>(T)});
            return d;
          },
          py::arg("qs"), py::arg("first_step"), py::arg("floor_step") = 1e-3,
          "Proves a sampled motion qs (T, n) clear at and between its samples (joined by straight joint segments; "
          "path_check.hpp): evaluated where a joint has travelled first_step (rad) since the last, each interval "
          "proven with the joints' total variation or halved. A dict as check_path's (without segments) and "
          "obstacle_lower (T,): a lower bound of the obstacle distance from each sample to the next");
}

}  // namespace snakehead::bindings
