// Index arrays from Python (shape lists, shape pairs) as C++ vectors, checked once: shared by the binders that
// take them.
#pragma once

#include <pybind11/numpy.h>

#include <array>
#include <string>
#include <vector>

#include "snakehead/model.hpp"  // InputError

namespace snakehead::bindings {

using IndexArray = pybind11::array_t<long, pybind11::array::c_style | pybind11::array::forcecast>;

// A (k,) index array; InputError naming ``what`` otherwise.
template <typename T = long>
std::vector<T> index_list(const char* what, const IndexArray& list) {
  if (list.ndim() != 1) throw InputError(std::string(what) + " must have shape (k,)");
  return {list.data(), list.data() + list.shape(0)};
}

// A (P, 2) array of index pairs; InputError naming ``what`` otherwise.
inline std::vector<std::array<long, 2>> index_pairs(const char* what, const IndexArray& pairs) {
  if (pairs.ndim() != 2 || pairs.shape(1) != 2) throw InputError(std::string(what) + " must have shape (P, 2)");
  std::vector<std::array<long, 2>> out;
  for (pybind11::ssize_t p = 0; p < pairs.shape(0); ++p) out.push_back({pairs.at(p, 0), pairs.at(p, 1)});
  return out;
}

}  // namespace snakehead::bindings
