// One binder per C++ header; module.cpp calls them all. Bindings are thin: no logic here.
#pragma once

#include <pybind11/pybind11.h>

namespace snakehead::bindings {
void bind_model(pybind11::module_& m);
void bind_trac_ik(pybind11::module_& m);
void bind_workspace(pybind11::module_& m);
void bind_support(pybind11::module_& m);
void bind_shape_set(pybind11::module_& m);
void bind_dynamics(pybind11::module_& m);
void bind_path_check(pybind11::module_& m);
void bind_zmp_check(pybind11::module_& m);
void bind_topp_ra(pybind11::module_& m);
void bind_tracking_fit(pybind11::module_& m);
void bind_limits(pybind11::module_& m);
void bind_core_threads(pybind11::module_& m);
void bind_neck_fit(pybind11::module_& m);
void bind_piecewise_polynomial(pybind11::module_& m);
void bind_limit_ratios(pybind11::module_& m);
void bind_terrain(pybind11::module_& m);
}  // namespace snakehead::bindings
