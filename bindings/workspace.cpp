#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <optional>

#include "bindings.hpp"
#include "snakehead/alpha_shape.hpp"
#include "snakehead/workspace.hpp"

namespace py = pybind11;

namespace snakehead::bindings {
namespace {

using RowMat3 = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

template <class T>
py::array_t<T> to_array(const std::vector<T>& v) {
  py::array_t<T> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

// Runs `fn` without the GIL; the progress callback takes it back only while it runs Python. An
// exception raised by the callback (KeyboardInterrupt from tqdm's loop, say), or by the truth test of
// what it returned, stops the sweep and is re-raised here. A false result cancels: _core.Cancelled.
template <class Fn>
auto without_gil(const py::object& progress, Fn fn) {
  ProgressCallback cb;
  if (!progress.is_none()) {
    cb = [progress](std::int64_t done, std::int64_t total) {
      py::gil_scoped_acquire gil;
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
      py::object r = progress(done, total);
      if (r.is_none()) return true;
      const int go_on = PyObject_IsTrue(r.ptr());  // Python's truth (numpy's bool_, 0/1, ...)
      if (go_on < 0) throw py::error_already_set();
      return go_on == 1;
    };
  }
  py::gil_scoped_release release;
  return fn(cb);
}

// The per-direction bits as a (voxels, bytes per voxel) uint8 array.
py::array_t<std::uint8_t> bits_array(const std::vector<std::uint8_t>& bits, std::size_t voxels, int tried) {
  const auto bytes = static_cast<py::ssize_t>(reached_bytes_per_voxel(tried));
  py::array_t<std::uint8_t> a({static_cast<py::ssize_t>(voxels), bytes});
  if (bits.size() != voxels * static_cast<std::size_t>(bytes)) throw std::logic_error("per-direction bits of the wrong size");
  std::copy(bits.begin(), bits.end(), a.mutable_data());
  return a;
}

py::dict map_to_dict(const ReachabilityMap& m) {
  py::dict d;
  d["centers"] = py::array_t<double>(py::array::ShapeContainer{static_cast<py::ssize_t>(m.centres.rows()), py::ssize_t{3}},
                                     m.centres.data());
  d["solved"] = to_array(m.solved);
  d["reached"] = bits_array(m.reached, m.voxel_ids.size(), m.tried);
  d["voxel_ids"] = to_array(m.voxel_ids);
  d["tried"] = m.tried;
  d["grid_origin"] = Eigen::Vector3d(m.grid.origin);
  d["grid_size"] = m.grid.side();
  d["grid_shape"] = std::vector<int>{m.grid.n, m.grid.n, m.grid.n};
  d["hull_voxels"] = m.hull_voxels;
  d["hull_facets"] = m.hull_facets;
  d["alpha"] = m.alpha;
  d["reach"] = m.reach;
  d["chain_hash"] = m.chain_hash;
  d["base"] = m.base;
  d["tip"] = m.tip;
  d["ik_calls"] = m.ik_calls;
  d["cheap_exits"] = m.cheap_exits;
  d["seconds"] = m.seconds;
  d["threads"] = m.threads_used;
  return d;
}

}  // namespace

void bind_workspace(py::module_& m) {
  py::class_<WorkspaceOptions>(m, "WorkspaceOptions", "Parameters of a reachability sweep (workspace.hpp).")
      .def(py::init<>())
      .def_readwrite("voxel_size", &WorkspaceOptions::voxel_size)
      .def_readwrite("directions", &WorkspaceOptions::directions)
      .def_readwrite("rolls", &WorkspaceOptions::rolls)
      .def_readwrite("any_roll", &WorkspaceOptions::any_roll)
      .def_readwrite("free_roll", &WorkspaceOptions::free_roll)
      .def_property(
          "approach_axis", [](const WorkspaceOptions& o) { return std::string(approach_axis_name(o.approach)); },
          [](WorkspaceOptions& o, const std::string& s) { o.approach = parse_approach_axis(s); })
      .def_readwrite("timeout", &WorkspaceOptions::timeout)
      .def_readwrite("epsilon", &WorkspaceOptions::epsilon)
      .def_readwrite("cloud_samples", &WorkspaceOptions::cloud_samples)
      .def_property(
          "hull", [](const WorkspaceOptions& o) { return std::string(hull_kind_name(o.hull)); },
          [](WorkspaceOptions& o, const std::string& s) { o.hull = parse_hull_kind(s); })
      .def_readwrite("shrink", &WorkspaceOptions::shrink)
      .def_property_readonly("map_shrink", &WorkspaceOptions::map_shrink)
      .def_readwrite("seed", &WorkspaceOptions::seed)
      .def_readwrite("threads", &WorkspaceOptions::threads)
      .def_readwrite("shard_index", &WorkspaceOptions::shard_index)
      .def_readwrite("shard_count", &WorkspaceOptions::shard_count)
      .def("validate", &WorkspaceOptions::validate)
      .def_property_readonly("poses_per_voxel", &WorkspaceOptions::poses_per_voxel);

  m.def("fibonacci_directions",
        [](int n) {
          const auto d = fibonacci_directions(n);
          RowMat3 out(static_cast<Eigen::Index>(d.size()), 3);
          for (std::size_t k = 0; k < d.size(); ++k) out.row(static_cast<Eigen::Index>(k)) = d[k].transpose();
          return out;
        },
        py::arg("n"), "n unit vectors spread evenly on the sphere (Fibonacci lattice), (n, 3)");
  m.def("approach_frame",
        [](const Eigen::Vector3d& point, const Eigen::Vector3d& direction, double roll, const std::string& axis) {
          return Eigen::Matrix4d(approach_frame(point, direction, roll, parse_approach_axis(axis)).matrix());
        },
        py::arg("point"), py::arg("direction"), py::arg("roll") = 0.0, py::arg("axis") = "x",
        "4x4 frame at point whose x- (or z-) axis is direction, rolled by roll rad about it");
  m.def("sample_tip_positions",
        [](const ChainModel& model, int samples, std::uint64_t seed) {
          std::vector<Eigen::Vector3d> p;
          {
            py::gil_scoped_release release;
            p = sample_tip_positions(model, samples, seed);
          }
          RowMat3 out(static_cast<Eigen::Index>(p.size()), 3);
          for (std::size_t k = 0; k < p.size(); ++k) out.row(static_cast<Eigen::Index>(k)) = p[k].transpose();
          return out;
        },
        py::arg("model"), py::arg("samples"), py::arg("seed"));
  m.def("convex_hull",
        [](const Eigen::Ref<const RowMat3>& points) {
          std::vector<Eigen::Vector3d> p(static_cast<std::size_t>(points.rows()));
          for (Eigen::Index k = 0; k < points.rows(); ++k) p[static_cast<std::size_t>(k)] = points.row(k).transpose();
          if (!points.allFinite()) throw InputError("points must be finite");
          const ConvexHull h = ConvexHull::of(p);
          py::dict d;
          d["normals"] = RowMat3(h.normals);
          d["offsets"] = Eigen::VectorXd(h.offsets);
          d["volume"] = h.volume;
          d["n_vertices"] = h.n_vertices;
          return d;
        },
        py::arg("points"), "qhull's hull of (n, 3) points: facet planes normal . x + offset <= 0 inside, volume");
  m.def("boundary",
        [](const Eigen::Ref<const RowMat3>& points, double shrink) {
          if (!points.allFinite()) throw InputError("points must be finite");
          std::vector<Eigen::Vector3d> p(static_cast<std::size_t>(points.rows()));
          for (Eigen::Index k = 0; k < points.rows(); ++k) p[static_cast<std::size_t>(k)] = points.row(k).transpose();
          AlphaShape a = [&] {
            py::gil_scoped_release release;
            return AlphaShape::boundary(p, shrink);
          }();
          py::dict d;
          d["alpha"] = a.alpha();
          d["critical_alpha"] = a.critical_alpha();
          d["spectrum_size"] = a.spectrum_size();
          d["tetrahedra"] = a.n_tetrahedra();
          d["solid_tetrahedra"] = a.n_solid_tetrahedra();
          d["boundary_facets"] = a.n_boundary_facets();
          d["regions"] = a.n_regions();
          d["volume"] = a.volume();
          return d;
        },
        py::arg("points"), py::arg("shrink") = 0.5,
        "The paper's boundary(P) of (n, 3) points (alpha_shape.hpp): its alpha and size, as a dict");
  m.def("boundary_voxels",
        [](const Eigen::Ref<const RowMat3>& points, double shrink, const Eigen::Vector3d& origin, double voxel, int n) {
          if (!points.allFinite()) throw InputError("points must be finite");
          std::vector<Eigen::Vector3d> p(static_cast<std::size_t>(points.rows()));
          for (Eigen::Index k = 0; k < points.rows(); ++k) p[static_cast<std::size_t>(k)] = points.row(k).transpose();
          VoxelGrid g;
          g.origin = origin;
          g.voxel = voxel;
          g.n = n;
          if (!(voxel > 0) || n < 1) throw InputError("the grid needs a positive voxel size and at least one voxel");
          return to_array(AlphaShape::boundary(p, shrink).voxels_inside(g));
        },
        py::arg("points"), py::arg("shrink"), py::arg("origin"), py::arg("voxel"), py::arg("n"),
        "Linear ids of the grid voxels whose centre lies inside the boundary of the points");
  m.def("save_map",
        [](const std::string& path, const std::string& command, const WorkspaceOptions& o,
           const Eigen::Ref<const RowMat3>& centres, std::vector<std::int32_t> solved, std::vector<std::int64_t> voxel_ids,
           std::optional<py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast>> reached, int tried,
           const Eigen::Vector3d& grid_origin, double grid_voxel, int grid_n, std::int64_t hull_voxels, int hull_facets,
           double alpha, double reach, const std::string& chain_hash, const std::string& base, const std::string& tip,
           std::int64_t ik_calls, std::int64_t cheap_exits, double seconds, int threads, const std::string& kind,
           std::optional<py::array_t<double, py::array::c_style | py::array::forcecast>> base_joints,
           std::optional<py::array_t<double, py::array::c_style | py::array::forcecast>> base_placements) {
          ReachabilityMap map;
          map.kind = kind;
          if (base_joints) {
            if (base_joints->ndim() != 3) throw InputError("base_joints must be (voxels, tried, k)");
            map.base_joint_count = static_cast<int>(base_joints->shape(2));
            map.base_joints.assign(base_joints->data(), base_joints->data() + base_joints->size());
          }
          if (base_placements) {
            if (base_placements->ndim() != 3) throw InputError("base_placements must be (voxels, tried, 3)");
            map.base_placements.assign(base_placements->data(), base_placements->data() + base_placements->size());
          }
          map.options = o;
          map.centres = centres;
          map.solved = std::move(solved);
          map.voxel_ids = std::move(voxel_ids);
          if (reached) map.reached.assign(reached->data(), reached->data() + reached->size());
          map.tried = tried;
          map.grid.origin = grid_origin;
          map.grid.voxel = grid_voxel;
          map.grid.n = grid_n;
          map.hull_voxels = hull_voxels;
          map.hull_facets = hull_facets;
          map.alpha = alpha;
          map.reach = reach;
          map.chain_hash = chain_hash;
          map.base = base;
          map.tip = tip;
          map.ik_calls = ik_calls;
          map.cheap_exits = cheap_exits;
          map.seconds = seconds;
          map.threads_used = threads;
          py::gil_scoped_release release;
          save_npz(map, path, command);
        },
        py::arg("path"), py::arg("command"), py::arg("options"), py::arg("centers"), py::arg("solved"),
        py::arg("voxel_ids"), py::arg("reached"), py::arg("tried"), py::arg("grid_origin"), py::arg("grid_voxel"),
        py::arg("grid_n"), py::arg("hull_voxels"), py::arg("hull_facets"), py::arg("alpha"), py::arg("reach"),
        py::arg("chain_hash"), py::arg("base"), py::arg("tip"), py::arg("ik_calls"), py::arg("cheap_exits"),
        py::arg("seconds"), py::arg("threads"), py::arg("kind") = std::string(kMapKindHead),
        py::arg("base_joints") = py::none(), py::arg("base_placements") = py::none(),
        "The one map writer (save_npz, also workspace_gen's): a map's arrays to an .npz that numpy.load reads");
  m.def("evaluate_voxels",
        [](const ChainModel& model, const WorkspaceOptions& o, const Eigen::Ref<const RowMat3>& centres,
           std::vector<std::uint64_t> stream_ids, const py::object& progress) {
          const RowMat3 c = centres;  // own copy: the sweep runs without the GIL
          VoxelEvaluation e = without_gil(progress, [&](const ProgressCallback& cb) {
            return evaluate_voxels(model, o, c, stream_ids, cb);
          });
          py::dict d;
          d["solved"] = to_array(e.solved);
          d["reached"] = bits_array(e.reached, e.solved.size(), e.tried);
          d["tried"] = e.tried;
          d["ik_calls"] = e.ik_calls;
          d["cheap_exits"] = e.cheap_exits;
          d["seconds"] = e.seconds;
          d["threads"] = e.threads_used;
          return d;
        },
        py::arg("model"), py::arg("options"), py::arg("centers"), py::arg("stream_ids"),
        py::arg("progress") = py::none(),
        "Algorithm 1's lines 9-21 for spheres at the given centres; progress(done, total) -> bool");
  m.def("compute_reachability",
        [](const ChainModel& model, const WorkspaceOptions& o, const py::object& progress) {
          ReachabilityMap r = without_gil(progress, [&](const ProgressCallback& cb) {
            return compute_reachability(model, o, cb);
          });
          return map_to_dict(r);
        },
        py::arg("model"), py::arg("options"), py::arg("progress") = py::none(),
        "Algorithm 1 over options' shard; returns the map's arrays and statistics as a dict");
}

}  // namespace snakehead::bindings
