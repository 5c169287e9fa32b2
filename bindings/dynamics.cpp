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
  if (!ok) throw InputError(std::string("newton_euler: ") + what + " has the wrong shape");
}
}  // namespace

void bind_dynamics(py::module_& m) {
  m.def(
      "newton_euler",
      [](Array frames, Array qd, Array qdd, std::vector<int> joint_child, Array axes, Array masses, Array coms,
         Array inertias, std::optional<Array> share, Eigen::Vector3d gravity_root) {
        expect_shape(frames, {-1, -1, 4, 4}, "frames (T, L, 4, 4)");
        const long T = static_cast<long>(frames.shape(0)), L = static_cast<long>(frames.shape(1));
        const long n = static_cast<long>(joint_child.size());
        expect_shape(qd, {T, n}, "qd (T, n)");
        expect_shape(qdd, {T, n}, "qdd (T, n)");
        expect_shape(axes, {n, 3}, "axes (n, 3)");
        expect_shape(masses, {L}, "masses (L,)");
        expect_shape(coms, {L, 3}, "coms (L, 3)");
        expect_shape(inertias, {L, 3, 3}, "inertias (L, 3, 3)");
        if (share) expect_shape(*share, {T, L}, "share (T, L)");
        RigidBodyChain chain;
        chain.joint_child = joint_child;
        for (long j = 0; j < n; ++j) chain.axis.emplace_back(axes.at(j, 0), axes.at(j, 1), axes.at(j, 2));
        for (long k = 0; k < L; ++k) {
          chain.mass.push_back(masses.at(k));
          chain.com.emplace_back(coms.at(k, 0), coms.at(k, 1), coms.at(k, 2));
          chain.inertia.push_back(Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(
              inertias.data() + 9 * k));
        }
        Array tau({static_cast<py::ssize_t>(T), static_cast<py::ssize_t>(n)});
        Array force({static_cast<py::ssize_t>(T), static_cast<py::ssize_t>(3)});
        Array moment({static_cast<py::ssize_t>(T), static_cast<py::ssize_t>(3)});
        double *tp = tau.mutable_data(), *fp = force.mutable_data(), *mp = moment.mutable_data();
        const double* sp = share ? share->data() : nullptr;
        {
          py::gil_scoped_release release;
          newton_euler(chain, frames.data(), qd.data(), qdd.data(), sp, gravity_root, T, L, tp, fp, mp);
        }
        return py::make_tuple(tau, force, moment);
      },
      py::arg("frames"), py::arg("qd"), py::arg("qdd"), py::arg("joint_child"), py::arg("axes"), py::arg("masses"),
      py::arg("coms"), py::arg("inertias"), py::arg("share"), py::arg("gravity_root"),
      "Newton-Euler with the root link still: joint torques (T, n) and the inertial wrench across the first joint "
      "(force (T, 3), moment about the root origin (T, 3), root axes)");
}

}  // namespace snakehead::bindings
