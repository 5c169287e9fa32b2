#include "bindings.hpp"

PYBIND11_MODULE(_core, m) {
  m.doc() = "snakehead's C++ core: chain model, kinematics, TRAC-IK, workspace sweep";
  snakehead::bindings::bind_model(m);
  snakehead::bindings::bind_trac_ik(m);
  snakehead::bindings::bind_workspace(m);
  snakehead::bindings::bind_support(m);
}
