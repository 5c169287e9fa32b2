#include <pybind11/numpy.h>

#include <string>

#include "bindings.hpp"
#include "snakehead/limit_ratios.hpp"
#include "snakehead/model.hpp"

namespace py = pybind11;

namespace snakehead::bindings {

namespace {

using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

void check_shape(const Array& a, std::initializer_list<py::ssize_t> shape, const char* name) {
  bool ok = a.ndim() == static_cast<py::ssize_t>(shape.size());
  py::ssize_t d = 0;
  for (py::ssize_t s : shape) ok = ok && a.shape(d++) == s;
  if (!ok) throw InputError(std::string("limit_ratios: ") + name + " has the wrong shape");
}

py::array_t<double> to_array(const std::vector<double>& v) {
  return py::array_t<double>(static_cast<py::ssize_t>(v.size()), v.data());
}

}  // namespace

void bind_limit_ratios(py::module_& m) {
  m.def(
      "limit_ratios",
      [](Array qd, Array qdd, Array tau, Array Pdot, Array Ldot, Array com, Array normal, Array offset,
         Array velocity, Array acceleration, Array torque, double Mg, double friction, double Mg_x, double Mg_y) {
        if (qd.ndim() != 2 || normal.ndim() != 3) throw InputError("limit_ratios: qd must be (N, n), normal (N, E, 2)");
        const py::ssize_t N = qd.shape(0), n = qd.shape(1), E = normal.shape(1);
        check_shape(qdd, {N, n}, "qdd");
        check_shape(tau, {N, n}, "tau");
        check_shape(Pdot, {N, 3}, "Pdot");
        check_shape(Ldot, {N, 3}, "Ldot");
        check_shape(com, {N, 3}, "com");
        check_shape(normal, {N, E, 2}, "normal");
        check_shape(offset, {N, E}, "offset");
        for (const auto* limit : {&velocity, &acceleration, &torque}) check_shape(*limit, {n}, "a limit");
        LimitRatios r;
        {
          py::gil_scoped_release release;
          r = limit_ratios(N, n, E, qd.data(), qdd.data(), tau.data(), Pdot.data(), Ldot.data(), com.data(),
                           normal.data(), offset.data(), velocity.data(), acceleration.data(), torque.data(), Mg,
                           friction, Mg_x, Mg_y);
        }
        py::dict out;
        out["velocity"] = to_array(r.velocity);
        out["acceleration"] = to_array(r.acceleration);
        out["torque"] = to_array(r.torque);
        out["friction"] = to_array(r.friction);
        out["zmp_margin"] = to_array(r.zmp_margin);
        return out;
      },
      py::arg("qd"), py::arg("qdd"), py::arg("tau"), py::arg("Pdot"), py::arg("Ldot"), py::arg("com"),
      py::arg("normal"), py::arg("offset"), py::arg("velocity"), py::arg("acceleration"), py::arg("torque"),
      py::arg("Mg"), py::arg("friction"), py::arg("Mg_x") = 0.0, py::arg("Mg_y") = 0.0,
      "Per sample (N,): the largest |value| / limit of qd, qdd and tau (N, n), the friction used "
      "(|dP_xy/dt - (Mg_x, Mg_y)| / (friction (Mg + dP_z/dt)), inf where the ground would pull; Mg_x, Mg_y: the "
      "weight along a slope's ground, zero on flat ground) and the ZMP's signed distance inside "
      "its polygon (normal (N, E, 2) inward, offset (N, E); -inf where the ground would pull): a dict of arrays.");
}

}  // namespace snakehead::bindings
