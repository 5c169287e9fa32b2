#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "snakehead/kinematics.hpp"
#include "snakehead/model.hpp"
#include "snakehead/urdf_input.hpp"

#include <optional>

namespace py = pybind11;

namespace snakehead::bindings {
namespace {

using ConstVec = Eigen::Ref<const Eigen::VectorXd>;
using RowMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

py::array_t<double> frames_to_array(const Frames& frames) {
  py::array_t<double> out({static_cast<py::ssize_t>(frames.size()), py::ssize_t{4}, py::ssize_t{4}});
  auto v = out.mutable_unchecked<3>();
  for (std::size_t k = 0; k < frames.size(); ++k)
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) v(k, r, c) = frames[k].matrix()(r, c);
  return out;
}

const char* type_name(JointType t) {
  switch (t) {
    case JointType::Revolute: return "revolute";
    case JointType::Continuous: return "continuous";
    case JointType::Prismatic: return "prismatic";
  }
  return "unknown";
}

}  // namespace

void bind_model(py::module_& m) {
  m.def("read_urdf_file", &read_urdf_file, py::arg("path"),
        "The text of a URDF file: ValueError unless a readable regular file of at most 8 MiB");
  m.def("urdf_root_link", &urdf_root_link, py::arg("urdf"),
        "The root link of a URDF (an XML document or a file path)");
  py::class_<ChainModel>(m, "ChainModel", "Immutable serial chain between two links of a URDF.")
      .def_static("from_urdf", &ChainModel::from_urdf, py::arg("urdf"), py::arg("base"), py::arg("tip"),
                  "urdf: an XML document or a file path")
      .def_property_readonly("n_joints", &ChainModel::n_joints)
      .def_property_readonly("base", &ChainModel::base_name)
      .def_property_readonly("tip", &ChainModel::tip_name)
      .def_property_readonly("joint_names", &ChainModel::joint_names)
      .def_property_readonly("joint_types",
                             [](const ChainModel& c) {
                               std::vector<std::string> t;
                               for (const auto& j : c.joints()) t.push_back(type_name(j.type));
                               return t;
                             })
      .def_property_readonly("lower", &ChainModel::lower)
      .def_property_readonly("upper", &ChainModel::upper)
      .def_property_readonly("effort",
                             [](const ChainModel& c) {
                               Eigen::VectorXd e(c.n_joints());
                               for (int i = 0; i < c.n_joints(); ++i) e[i] = c.joints()[i].effort;
                               return e;
                             })
      .def_property_readonly("velocity",
                             [](const ChainModel& c) {
                               Eigen::VectorXd e(c.n_joints());
                               for (int i = 0; i < c.n_joints(); ++i) e[i] = c.joints()[i].velocity;
                               return e;
                             })
      .def_property_readonly("joint_axes",
                             [](const ChainModel& c) {
                               RowMat v(c.n_joints(), 3);
                               for (int i = 0; i < c.n_joints(); ++i) v.row(i) = c.segments()[i].axis;
                               return v;
                             },
                             "(n, 3) unit joint axes, each in the frame of the link the joint moves")
      .def_property_readonly("joint_child_links",
                             [](const ChainModel& c) {
                               std::vector<int> idx;
                               for (const auto& s : c.segments()) idx.push_back(c.link_index(s.link));
                               return idx;
                             },
                             "index into link_names of the link each joint moves (its frame is the joint frame)")
      .def_property_readonly("reach", &ChainModel::reach)
      .def_property_readonly("hash", &ChainModel::hash, "digest of the kinematics (what maps depend on)")
      .def_property_readonly("body_hash", &ChainModel::body_hash,
                             "digest of the links' masses, centres of mass, inertias and collision shapes")
      .def_property_readonly("total_mass", &ChainModel::total_mass, "sum of the link masses (kg); may be 0")
      .def_property_readonly("link_names",
                             [](const ChainModel& c) {
                               std::vector<std::string> n;
                               for (const auto& l : c.links()) n.push_back(l.name);
                               return n;
                             })
      .def_property_readonly("link_masses",
                             [](const ChainModel& c) {
                               Eigen::VectorXd v(c.links().size());
                               for (std::size_t k = 0; k < c.links().size(); ++k) v[k] = c.links()[k].mass;
                               return v;
                             })
      .def_property_readonly("link_coms",
                             [](const ChainModel& c) {
                               RowMat v(c.links().size(), 3);
                               for (std::size_t k = 0; k < c.links().size(); ++k) v.row(k) = c.links()[k].com;
                               return v;
                             })
      .def_property_readonly("link_inertias",
                             [](const ChainModel& c) {
                               py::array_t<double> out({static_cast<py::ssize_t>(c.links().size()), py::ssize_t{3},
                                                        py::ssize_t{3}});
                               auto v = out.mutable_unchecked<3>();
                               for (std::size_t k = 0; k < c.links().size(); ++k)
                                 for (int r = 0; r < 3; ++r)
                                   for (int s = 0; s < 3; ++s) v(k, r, s) = c.links()[k].inertia(r, s);
                               return out;
                             })
      .def_property_readonly(
          "link_collisions",
          [](const ChainModel& c) {
            static const char* kinds[] = {"box", "cylinder", "sphere", "mesh"};
            py::list out;
            for (const auto& l : c.links()) {
              py::list shapes;
              for (const CollisionElement& e : l.collisions)
                shapes.append(py::make_tuple(kinds[static_cast<int>(e.kind)], Eigen::Matrix4d(e.origin.matrix()),
                                             Eigen::Vector3d(e.size), e.filename));
              out.append(shapes);
            }
            return out;
          },
          "per link (link_names order) its <collision> elements as (kind, origin 4x4 in the link frame, size, mesh "
          "filename): kind 'box' (size = extents), 'cylinder' (radius, length, 0; axis z), 'sphere' (radius, 0, 0) "
          "or 'mesh' (size = scale; filename as written in the URDF)")
      .def("fk",
           [](const ChainModel& c, ConstVec q) {
             c.check_configuration(q);
             return Eigen::Matrix4d(forward_kinematics(c, q).matrix());
           },
           py::arg("q"))
      .def("fk_all",
           [](const ChainModel& c, ConstVec q) {
             c.check_configuration(q);
             Frames f;
             link_frames(c, q, f);
             return frames_to_array(f);
           },
           py::arg("q"))
      .def("fk_all_many",
           [](const ChainModel& c, const Eigen::Ref<const RowMat>& qs, std::optional<Eigen::Matrix4d> origin) {
             if (qs.cols() != c.n_joints())
               throw InputError("configurations have " + std::to_string(qs.cols()) + " columns; the chain has " +
                                std::to_string(c.n_joints()) + " joints");
             for (Eigen::Index t = 0; t < qs.rows(); ++t) c.check_configuration(qs.row(t).transpose(), "q");
             const auto n_links = static_cast<py::ssize_t>(c.links().size());
             py::array_t<double> out({static_cast<py::ssize_t>(qs.rows()), n_links, py::ssize_t{4}, py::ssize_t{4}});
             double* data = out.mutable_data();
             {
               py::gil_scoped_release release;
               Frames f;
               const Eigen::Matrix4d O = origin ? *origin : Eigen::Matrix4d::Identity();
               for (Eigen::Index t = 0; t < qs.rows(); ++t)
                 world_link_frames(c, O, qs.row(t).transpose(), f, data + t * n_links * 16);
             }
             return out;
           },
           py::arg("qs"), py::arg("origin") = py::none(),
           "Every link's pose (T, n_links, 4, 4) for configurations qs (T, n), in the chain's base frame or, given "
           "origin (the base frame's pose, 4x4), in origin's frame")
      .def("jacobian",
           [](const ChainModel& c, ConstVec q) {
             c.check_configuration(q);
             Jacobian j;
             Eigen::Isometry3d tip;
             tip_jacobian(c, q, j, tip);
             return Eigen::MatrixXd(j);
           },
           py::arg("q"))
      .def("kdl_fk",
           [](const ChainModel& c, ConstVec q) {
             c.check_configuration(q);
             return Eigen::Matrix4d(kdl_forward_kinematics(c, q).matrix());
           },
           py::arg("q"), "Reference FK through KDL's ChainFkSolverPos_recursive.")
      .def("kdl_jacobian",
           [](const ChainModel& c, ConstVec q) {
             c.check_configuration(q);
             return Eigen::MatrixXd(kdl_jacobian(c, q));
           },
           py::arg("q"), "Reference Jacobian through KDL's ChainJntToJacSolver.");
}

}  // namespace snakehead::bindings
