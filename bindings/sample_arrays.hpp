// Sample arrays between Python and the core, shared by the binders of the path check and the ZMP check: (T, n)
// configurations in, checked once; flat vectors out as numpy arrays.
#pragma once

#include <pybind11/numpy.h>

#include <algorithm>
#include <string>
#include <vector>

#include "snakehead/model.hpp"  // InputError

namespace snakehead::bindings {

using SampleArray = pybind11::array_t<double, pybind11::array::c_style | pybind11::array::forcecast>;

// T, the number of rows of a (T, n) array; InputError naming `what` otherwise.
inline long samples_of(const char* what, const SampleArray& q, long n) {
  if (q.ndim() != 2 || q.shape(1) != n)
    throw InputError(std::string(what) + " must have shape (T, " + std::to_string(n) + ")");
  return static_cast<long>(q.shape(0));
}

// v as a numpy array of the given shape (v holds its product of values).
inline pybind11::array_t<double> array_of(const std::vector<double>& v, std::vector<pybind11::ssize_t> shape) {
  pybind11::array_t<double> out(shape);
  std::copy(v.begin(), v.end(), out.mutable_data());
  return out;
}

}  // namespace snakehead::bindings
