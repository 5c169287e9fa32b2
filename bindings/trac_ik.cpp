#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "snakehead/kinematics.hpp"
#include "snakehead/trac_ik.hpp"

namespace py = pybind11;

namespace snakehead::bindings {
namespace {

using ConstVec = Eigen::Ref<const Eigen::VectorXd>;
using RowMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

Eigen::Isometry3d to_isometry(const Eigen::Matrix4d& m) {
  Eigen::Isometry3d t;
  t.matrix() = m;
  return t;
}

Vector6d to_bounds(const Eigen::VectorXd& b) {
  if (b.size() != 6) throw InputError("bounds must have 6 entries (vx vy vz wx wy wz), got " + std::to_string(b.size()));
  return b;
}

IKAlgorithm algorithm_from_string(const std::string& name) {
  if (name == "TRAC-IK") return IKAlgorithm::TracIK;
  if (name == "KDL-RR") return IKAlgorithm::KdlRR;
  if (name == "SQP") return IKAlgorithm::Sqp;
  throw InputError("unknown algorithm '" + name + "'; expected TRAC-IK, KDL-RR or SQP");
}

}  // namespace

void bind_trac_ik(py::module_& m) {
  py::class_<TracIK, std::shared_ptr<TracIK>>(m, "TracIK",
                                              "TRAC-IK on a chain: KDL-RR and SLSQP raced in a kept thread pool.")
      .def(py::init([](const ChainModel& model, double timeout, double epsilon, const std::string& solve_type,
                       const Eigen::VectorXd& bounds, std::optional<std::uint64_t> seed) {
             TracIKOptions o;
             o.timeout = timeout;
             o.epsilon = epsilon;
             o.solve_type = solve_type_from_string(solve_type);
             o.bounds = to_bounds(bounds);
             o.seed = seed;
             return std::make_shared<TracIK>(model, o);
           }),
           py::arg("model"), py::arg("timeout"), py::arg("epsilon"), py::arg("solve_type"), py::arg("bounds"),
           py::arg("seed") = py::none())
      .def_property_readonly("n_joints", &TracIK::n_joints)
      .def_property_readonly("n_workers", &TracIK::n_workers)
      .def_property_readonly("timeout", [](const TracIK& s) { return s.options().timeout; })
      .def_property_readonly("epsilon", [](const TracIK& s) { return s.options().epsilon; })
      .def_property_readonly("solve_type", [](const TracIK& s) { return std::string(to_string(s.options().solve_type)); })
      .def_property_readonly("bounds", [](const TracIK& s) { return Eigen::VectorXd(s.options().bounds); })
      .def_property_readonly("seed", [](const TracIK& s) { return s.options().seed; })
      .def_property_readonly("lower", [](const TracIK& s) { return s.model().lower(); })
      .def_property_readonly("upper", [](const TracIK& s) { return s.model().upper(); })
      .def(
          "ik",
          [](const TracIK& s, const Eigen::Matrix4d& pose, const Eigen::VectorXd& q_init,
             std::optional<Eigen::VectorXd> bounds, std::optional<double> timeout, const std::string& algorithm) {
            TracIKOptions o = s.options();
            if (bounds) o.bounds = to_bounds(*bounds);
            if (timeout) o.timeout = *timeout;
            const IKAlgorithm alg = algorithm_from_string(algorithm);
            IKResult r;
            {
              py::gil_scoped_release release;
              r = s.solve_ex(to_isometry(pose), q_init, o, alg);
            }
            return py::make_tuple(r.found, r.q, r.seconds);
          },
          py::arg("pose"), py::arg("q_init"), py::arg("bounds") = py::none(), py::arg("timeout") = py::none(),
          py::arg("algorithm") = "TRAC-IK",
          "Returns (found, q, seconds); q is q_init when nothing was found.")
      .def(
          "ik_many",
          [](const TracIK& s, py::array_t<double, py::array::c_style | py::array::forcecast> poses,
             const Eigen::Ref<const RowMat>& q_inits, std::optional<std::vector<std::uint64_t>> streams) {
            if (poses.ndim() != 3 || poses.shape(1) != 4 || poses.shape(2) != 4)
              throw InputError("poses must have shape (T, 4, 4)");
            const auto T = static_cast<std::size_t>(poses.shape(0));
            if (static_cast<std::size_t>(q_inits.rows()) != T || q_inits.cols() != s.n_joints())
              throw InputError("q_inits must have shape (" + std::to_string(T) + ", " + std::to_string(s.n_joints()) +
                               ")");
            std::vector<Eigen::Isometry3d, Eigen::aligned_allocator<Eigen::Isometry3d>> targets(T);
            auto v = poses.unchecked<3>();
            for (std::size_t k = 0; k < T; ++k)
              for (int r = 0; r < 4; ++r)
                for (int c = 0; c < 4; ++c) targets[k].matrix()(r, c) = v(k, r, c);
            const Eigen::MatrixXd qi = q_inits.transpose();
            Eigen::MatrixXd q_out;
            std::vector<bool> ok;
            {
              py::gil_scoped_release release;
              s.solve_many(targets, qi, q_out, ok, streams ? &*streams : nullptr);
            }
            RowMat q = q_out.transpose();
            py::array_t<bool> okv(static_cast<py::ssize_t>(T));
            auto o = okv.mutable_unchecked<1>();
            for (std::size_t k = 0; k < T; ++k) o(k) = ok[k];
            return py::make_tuple(q, okv);
          },
          py::arg("poses"), py::arg("q_inits"), py::arg("streams") = py::none())
      .def(
          "fk",
          [](const TracIK& s, const ConstVec& q) {
            s.model().check_configuration(q);
            return Eigen::Matrix4d(forward_kinematics(s.model(), q).matrix());
          },
          py::arg("q"));

  m.def(
      "kdl_nr_jl_ik",
      [](const ChainModel& model, const Eigen::Matrix4d& pose, const Eigen::VectorXd& q_init, double timeout,
         double epsilon) {
        Eigen::VectorXd q;
        bool ok;
        {
          py::gil_scoped_release release;
          ok = kdl_nr_jl_ik(model, to_isometry(pose), q_init, q, timeout, epsilon);
        }
        return py::make_tuple(ok, q);
      },
      py::arg("model"), py::arg("pose"), py::arg("q_init"), py::arg("timeout") = 0.005, py::arg("epsilon") = 1e-5,
      "KDL's ChainIkSolverPos_NR_JL from q_init until converged or timeout: (found, q).");

  m.def(
      "pose_error",
      [](const Eigen::Matrix4d& target, const Eigen::Matrix4d& current) {
        check_pose(to_isometry(target), "target");
        check_pose(to_isometry(current), "current");
        return Eigen::VectorXd(pose_error(to_isometry(target), to_isometry(current)));
      },
      py::arg("target"), py::arg("current"),
      "The IK pose error (vx vy vz wx wy wz) of `current` relative to `target`, in the target frame.");
}

}  // namespace snakehead::bindings
