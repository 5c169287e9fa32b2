#include <pybind11/numpy.h>

#include "bindings.hpp"
#include "snakehead/box_collision.hpp"
#include "snakehead/model.hpp"

namespace py = pybind11;

namespace snakehead::bindings {
namespace {

using Doubles = py::array_t<double, py::array::c_style | py::array::forcecast>;
// Pairs: integers only (no forcecast, so that a float index is a TypeError rather than truncated).
using Indices = py::array_t<long, py::array::c_style>;

struct Sizes {
  long T, k, P;
};

// The shapes box_pair_gaps and box_pair_min_gaps take (their values the core checks).
Sizes check_shapes(const Doubles& centres, const Doubles& rotations, const Doubles& half_extents,
                   const Indices& pairs) {
  if (centres.ndim() != 3 || centres.shape(2) != 3) throw InputError("box_pair_gaps: centres must have shape (T, k, 3)");
  const long T = static_cast<long>(centres.shape(0)), k = static_cast<long>(centres.shape(1));
  if (rotations.ndim() != 4 || rotations.shape(0) != T || rotations.shape(1) != k || rotations.shape(2) != 3 ||
      rotations.shape(3) != 3)
    throw InputError("box_pair_gaps: rotations must have shape (T, k, 3, 3) like centres");
  if (half_extents.ndim() != 2 || half_extents.shape(0) != k || half_extents.shape(1) != 3)
    throw InputError("box_pair_gaps: half_extents must have shape (k, 3) like centres");
  if (pairs.ndim() != 2 || pairs.shape(1) != 2) throw InputError("box_pair_gaps: pairs must have shape (P, 2)");
  return {T, k, static_cast<long>(pairs.shape(0))};
}

}  // namespace

void bind_box_collision(py::module_& m) {
  m.def(
      "box_pair_gaps",
      [](Doubles centres, Doubles rotations, Doubles half_extents, Indices pairs) {
        const Sizes n = check_shapes(centres, rotations, half_extents, pairs);
        py::array_t<double> gaps({static_cast<py::ssize_t>(n.T), static_cast<py::ssize_t>(n.P)});
        double* out = gaps.mutable_data();
        {
          py::gil_scoped_release release;
          box_pair_gaps(centres.data(), rotations.data(), half_extents.data(), pairs.data(), n.T, n.k, n.P, out);
        }
        return gaps;
      },
      py::arg("centres"), py::arg("rotations"), py::arg("half_extents"), py::arg("pairs"),
      "Separating-axis gaps (m) of pairs of boxes at T samples: centres (T, k, 3), rotations (T, k, 3, 3), "
      "half_extents (k, 3), pairs (P, 2) box indices -> (T, P); > 0 apart (a lower bound of the distance), "
      "<= 0 overlapping (minus the penetration depth along the best axis)");
  m.def(
      "box_pair_min_gaps",
      [](Doubles centres, Doubles rotations, Doubles half_extents, Indices pairs) {
        const Sizes n = check_shapes(centres, rotations, half_extents, pairs);
        py::array_t<double> min_gaps(static_cast<py::ssize_t>(n.T));
        double* out = min_gaps.mutable_data();
        {
          py::gil_scoped_release release;
          box_pair_min_gaps(centres.data(), rotations.data(), half_extents.data(), pairs.data(), n.T, n.k, n.P, out);
        }
        return min_gaps;
      },
      py::arg("centres"), py::arg("rotations"), py::arg("half_extents"), py::arg("pairs"),
      "The smallest of box_pair_gaps' gaps at each sample: (T,), +inf when there is no pair");
}

}  // namespace snakehead::bindings
