#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "bindings.hpp"
#include "index_arrays.hpp"
#include "sample_arrays.hpp"
#include "snakehead/zmp_check.hpp"

namespace py = pybind11;

namespace snakehead::bindings {

void bind_zmp_check(py::module_& m) {
  using Doubles = SampleArray;
  using Indices = IndexArray;
  py::class_<ZmpPrefix, std::shared_ptr<ZmpPrefix>>(
      m, "ZmpPrefix",
      "What zmp_check computed sample by sample over the first samples of a motion, for a later check of a motion "
      "that begins with the same samples (zmp_check.hpp); immutable")
      .def_property_readonly("samples", &ZmpPrefix::size, "how many samples it holds");

  m.def(
      "zmp_check",
      [](const PathChecker& c, const Doubles& t, const Doubles& q, const Doubles& qd, const Indices& contact_shapes,
         long points_per_shape, const Indices& clearance_shapes, bool ground_key, std::vector<int> key_joints,
         double tolerance, long chunk, Eigen::Vector3d gravity, std::optional<std::shared_ptr<const ZmpPrefix>> resume,
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
      "The ZMP check of a sampled motion (Eqs. 25-40) in one pass (zmp_check.hpp): a dict of zmp (T, 2), margin "
      "(T,), P, L, com (T, 3) and clearance (T,): the lowest z of clearance_shapes; gravity (3,) m/s^2 in the ground "
      "frame (BasePlacement.gravity). resume: a ZmpPrefix whose samples this motion begins with (taken over when "
      "everything it was made from is the same, to the bit: resumed says how many samples); keep > 0: kept is the "
      "ZmpPrefix of the first keep samples (else None)");
}

}  // namespace snakehead::bindings
