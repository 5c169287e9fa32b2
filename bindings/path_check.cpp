#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <functional>
#include <optional>
#include <string>

#include "bindings.hpp"
#include "index_arrays.hpp"
#include "snakehead/path_check.hpp"

namespace py = pybind11;

namespace snakehead::bindings {

namespace {

using Doubles = py::array_t<double, py::array::c_style | py::array::forcecast>;
using Indices = IndexArray;

long samples_of(const char* what, const Doubles& q, long n) {
  if (q.ndim() != 2 || q.shape(1) != n)
    throw InputError(std::string(what) + " must have shape (T, " + std::to_string(n) + ")");
  return static_cast<long>(q.shape(0));
}

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

py::array_t<double> array_of(const std::vector<double>& v, std::vector<py::ssize_t> shape) {
  py::array_t<double> out(shape);
  std::copy(v.begin(), v.end(), out.mutable_data());
  return out;
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

  py::class_<ZmpPrefix, std::shared_ptr<ZmpPrefix>>(
      m, "ZmpPrefix",
      "What zmp_check computed sample by sample over the first samples of a motion, for a later check of a motion "
      "that begins with the same samples (path_check.hpp); immutable")
      .def_property_readonly("samples", &ZmpPrefix::size, "how many samples it holds");

  m.def(
      "zmp_check",
      [](const PathChecker& c, const Doubles& t, const Doubles& q, const Doubles& qd, const Indices& contact_shapes,
         long points_per_shape, const Indices& clearance_shapes, bool ground_key, std::vector<int> key_joints,
         double tolerance, long chunk, double gravity, std::optional<std::shared_ptr<const ZmpPrefix>> resume,
         long keep) {
        const long n = c.n_joints();
        const long T = samples_of("q", q, n);
        if (t.ndim() != 1 || t.shape(0) != T) throw InputError("t must have shape (T,) like q");
        if (samples_of("qd", qd, n) != T) throw InputError("qd must have the shape of q");
        ZmpCheckSpec spec;
        spec.contact_shapes = index_list("contact_shapes", contact_shapes);
        spec.points_per_shape = points_per_shape;
        spec.clearance_shapes = index_list("clearance_shapes", clearance_shapes);
        spec.ground_key = ground_key;
        spec.key_joints = std::move(key_joints);
        spec.tolerance = tolerance;
        spec.chunk = chunk;
        spec.gravity = gravity;
        ZmpCheck z;
        std::shared_ptr<ZmpPrefix> kept = keep > 0 ? std::make_shared<ZmpPrefix>() : nullptr;
        {
          py::gil_scoped_release release;
          const RigidBodyChain chain = chain_dynamics(c.model());
          z = zmp_check(c, chain, spec, t.data(), q.data(), qd.data(), T, resume ? resume->get() : nullptr, keep,
                        kept.get());
        }
        const auto N = static_cast<py::ssize_t>(T);
        py::dict d;
        d["zmp"] = array_of(z.zmp, {N, 2});
        d["margin"] = array_of(z.margin, {N});
        d["P"] = array_of(z.linear, {N, 3});
        d["L"] = array_of(z.angular, {N, 3});
        d["com"] = array_of(z.com, {N, 3});
        d["clearance"] = array_of(z.clearance, {N});
        d["resumed"] = z.resumed;
        d["kept"] = kept ? py::cast(std::shared_ptr<const ZmpPrefix>(kept)) : py::none();
        return d;
      },
      py::arg("checker"), py::arg("t"), py::arg("q"), py::arg("qd"), py::arg("contact_shapes"),
      py::arg("points_per_shape"), py::arg("clearance_shapes"), py::arg("ground_key"), py::arg("key_joints"),
      py::arg("tolerance"), py::arg("chunk"), py::arg("gravity"), py::arg("resume") = py::none(), py::arg("keep") = 0,
      "The ZMP check of a sampled motion (Eqs. 25-40) in one pass (path_check.hpp): a dict of zmp (T, 2), margin "
      "(T,), P, L, com (T, 3) and clearance (T,): the lowest z of clearance_shapes; gravity (m/s^2) from "
      "snakehead.model.physics.GRAVITY. resume: a ZmpPrefix whose samples this motion begins with (taken over when "
      "everything it was made from is the same, to the bit: resumed says how many samples); keep > 0: kept is the "
      "ZmpPrefix of the first keep samples (else None)");
}

}  // namespace snakehead::bindings
