#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <optional>

#include "bindings.hpp"
#include "snakehead/dynamics.hpp"
#include "snakehead/model.hpp"

namespace py = pybind11;

namespace snakehead::bindings {

namespace {
using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

void expect_shape(const Array& a, std::initializer_list<py::ssize_t> shape, const char* what) {
  bool ok = a.ndim() == static_cast<py::ssize_t>(shape.size());
  py::ssize_t i = 0;
  for (py::ssize_t s : shape) {
    ok = ok && (s < 0 || a.shape(i) == s);  // -1: any size
    ++i;
  }
  if (!ok) throw InputError(std::string(what) + " has the wrong shape");
}
// The chain's constant data from numpy arrays (shapes checked by the caller).
RigidBodyChain make_chain(const std::vector<int>& joint_child, const Array& axes, const Array& masses,
                          const Array& coms, const Array& inertias) {
  RigidBodyChain chain;
  chain.joint_child = joint_child;
  for (py::ssize_t j = 0; j < axes.shape(0); ++j) chain.axis.emplace_back(axes.at(j, 0), axes.at(j, 1), axes.at(j, 2));
  for (py::ssize_t k = 0; k < masses.shape(0); ++k) {
    chain.mass.push_back(masses.at(k));
    chain.com.emplace_back(coms.at(k, 0), coms.at(k, 1), coms.at(k, 2));
    chain.inertia.push_back(Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(inertias.data() + 9 * k));
  }
  return chain;
}
// make_chain after checking the arrays' shapes against n joints and L links.
RigidBodyChain checked_chain(const std::vector<int>& joint_child, const Array& axes, const Array& masses,
                             const Array& coms, const Array& inertias, long L) {
  const long n = static_cast<long>(joint_child.size());
  expect_shape(axes, {n, 3}, "axes (n, 3)");
  expect_shape(masses, {L}, "masses (L,)");
  expect_shape(coms, {L, 3}, "coms (L, 3)");
  expect_shape(inertias, {L, 3, 3}, "inertias (L, 3, 3)");
  return make_chain(joint_child, axes, masses, coms, inertias);
}
}  // namespace

void bind_dynamics(py::module_& m) {
  m.def(
      "newton_euler",
      [](Array frames, Array qd, Array qdd, std::vector<int> joint_child, Array axes, Array masses, Array coms,
         Array inertias, std::optional<Array> share, Eigen::Vector3d gravity) {
        expect_shape(frames, {-1, -1, 4, 4}, "frames (T, L, 4, 4)");
        const long T = static_cast<long>(frames.shape(0)), L = static_cast<long>(frames.shape(1));
        const long n = static_cast<long>(joint_child.size());
        expect_shape(qd, {T, n}, "qd (T, n)");
        expect_shape(qdd, {T, n}, "qdd (T, n)");
        if (share) expect_shape(*share, {T, L}, "share (T, L)");
        const RigidBodyChain chain = checked_chain(joint_child, axes, masses, coms, inertias, L);
        Array tau({static_cast<py::ssize_t>(T), static_cast<py::ssize_t>(n)});
        Array force({static_cast<py::ssize_t>(T), static_cast<py::ssize_t>(3)});
        Array moment({static_cast<py::ssize_t>(T), static_cast<py::ssize_t>(3)});
        double *tp = tau.mutable_data(), *fp = force.mutable_data(), *mp = moment.mutable_data();
        const double* sp = share ? share->data() : nullptr;
        {
          py::gil_scoped_release release;
          newton_euler(chain, frames.data(), qd.data(), qdd.data(), sp, gravity, T, L, tp, fp, mp);
        }
        return py::make_tuple(tau, force, moment);
      },
      py::arg("frames"), py::arg("qd"), py::arg("qdd"), py::arg("joint_child"), py::arg("axes"), py::arg("masses"),
      py::arg("coms"), py::arg("inertias"), py::arg("share"), py::arg("gravity"),
      "Newton-Euler with the root link still: joint torques (T, n) and the inertial wrench across the first joint "
      "(force (T, 3), moment about the frames' origin (T, 3), in their axes; frames in an inertial frame where the "
      "root link is still)");
  m.def(
      "newton_euler_along",
      [](const ChainModel& model, Eigen::Matrix4d origin, Array q, Array qd, Array qdd, std::vector<int> joint_child,
         Array axes, Array masses, Array coms, Array inertias, std::optional<std::vector<int>> lift_links,
         std::optional<Array> lift_points, double ramp, Eigen::Vector3d gravity) {
        const long n = static_cast<long>(joint_child.size());
        const long L = static_cast<long>(model.links().size());
        expect_shape(q, {-1, n}, "q (T, n)");
        const long T = static_cast<long>(q.shape(0));
        expect_shape(qd, {T, n}, "qd (T, n)");
        expect_shape(qdd, {T, n}, "qdd (T, n)");
        const RigidBodyChain chain = checked_chain(joint_child, axes, masses, coms, inertias, L);
        std::optional<LiftPoints> lift;
        if (lift_links) {
          if (!lift_points) throw InputError("lift_points are needed with lift_links");
          const auto k = static_cast<py::ssize_t>(lift_links->size());
          expect_shape(*lift_points, {k, -1, 3}, "lift_points (k, M, 3)");
          lift.emplace();
          lift->link = *lift_links;
          lift->ramp = ramp;
          for (py::ssize_t i = 0; i < k; ++i) {
            std::vector<Eigen::Vector3d> pts;
            for (py::ssize_t j = 0; j < lift_points->shape(1); ++j)
              pts.emplace_back(lift_points->at(i, j, 0), lift_points->at(i, j, 1), lift_points->at(i, j, 2));
            lift->points.push_back(std::move(pts));
          }
        }
        const auto Ts = static_cast<py::ssize_t>(T);
        Array tau({Ts, static_cast<py::ssize_t>(n)}), force({Ts, py::ssize_t{3}}), moment({Ts, py::ssize_t{3}}),
            com({Ts, py::ssize_t{3}});
        double *tp = tau.mutable_data(), *fp = force.mutable_data(), *mp = moment.mutable_data(),
               *cp = com.mutable_data();
        {
          py::gil_scoped_release release;
          newton_euler_along(model, origin, chain, lift ? &*lift : nullptr, q.data(), qd.data(), qdd.data(), gravity,
                             T, tp, fp, mp, cp);
        }
        return py::make_tuple(tau, force, moment, com);
      },
      py::arg("model"), py::arg("origin"), py::arg("q"), py::arg("qd"), py::arg("qdd"), py::arg("joint_child"),
      py::arg("axes"), py::arg("masses"), py::arg("coms"), py::arg("inertias"), py::arg("lift_links"),
      py::arg("lift_points"), py::arg("ramp"), py::arg("gravity"),
      "newton_euler along configurations q (T, n), the link frames (origin times the model's FK) and the lifted "
      "shares (lift_links, lift_points (k, M, 3) in the links' frames, ramp m; None: every weight in full) computed "
      "in the core: torques (T, n), the inertial wrench across the first joint (force, moment (T, 3)) and the "
      "centre of mass (T, 3)");
  m.def(
      "center_of_mass",
      [](Array frames, Array masses, Array coms) {
        expect_shape(frames, {-1, -1, 4, 4}, "frames (T, L, 4, 4)");
        const long T = static_cast<long>(frames.shape(0)), L = static_cast<long>(frames.shape(1));
        expect_shape(masses, {L}, "masses (L,)");
        expect_shape(coms, {L, 3}, "coms (L, 3)");
        Array c({static_cast<py::ssize_t>(T), py::ssize_t{3}});
        double* cp = c.mutable_data();
        {
          py::gil_scoped_release release;
          center_of_mass(frames.data(), masses.data(), coms.data(), T, L, cp);
        }
        return c;
      },
      py::arg("frames"), py::arg("masses"), py::arg("coms"),
      "The centre of mass (Eq. 23) of each sample (T, 3) from the links' frames (T, L, 4, 4), masses (L,) and centres "
      "of mass in the links' frames (L, 3): summed link by link in a fixed order, without BLAS, so that a sample's "
      "numbers do not depend on the samples around it, the machine or the thread count");
  m.def(
      "momenta",
      [](Array frames, Array qd, std::vector<int> joint_child, Array axes, Array masses, Array coms, Array inertias) {
        expect_shape(frames, {-1, -1, 4, 4}, "frames (T, L, 4, 4)");
        const long T = static_cast<long>(frames.shape(0)), L = static_cast<long>(frames.shape(1));
        const long n = static_cast<long>(joint_child.size());
        expect_shape(qd, {T, n}, "qd (T, n)");
        const RigidBodyChain chain = checked_chain(joint_child, axes, masses, coms, inertias, L);
        Array P({static_cast<py::ssize_t>(T), py::ssize_t{3}});
        Array Lm({static_cast<py::ssize_t>(T), py::ssize_t{3}});
        Array c({static_cast<py::ssize_t>(T), py::ssize_t{3}});
        double *pp = P.mutable_data(), *lp = Lm.mutable_data(), *cp = c.mutable_data();
        {
          py::gil_scoped_release release;
          momenta(chain, frames.data(), qd.data(), T, L, pp, lp, cp);
        }
        return py::make_tuple(P, Lm, c);
      },
      py::arg("frames"), py::arg("qd"), py::arg("joint_child"), py::arg("axes"), py::arg("masses"), py::arg("coms"),
      py::arg("inertias"),
      "The momenta of Eqs. 25-31 and the CoM: P, L about the frames' origin, c, (T, 3) each");
}

}  // namespace snakehead::bindings
