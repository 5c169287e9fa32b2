#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "snakehead/model.hpp"
#include "snakehead/shape_set.hpp"

namespace py = pybind11;

namespace snakehead::bindings {
namespace {

using Doubles = py::array_t<double, py::array::c_style | py::array::forcecast>;
// Indices: integers only (no forcecast, so that a float index is a TypeError rather than truncated).
using Indices = py::array_t<long, py::array::c_style>;

const char* const kKindNames[] = {"box", "cylinder", "sphere", "convex"};

ShapeKind kind_of(const std::string& name) {
  for (int k = 0; k < 4; ++k)
    if (name == kKindNames[k]) return static_cast<ShapeKind>(k);
  throw InputError("ShapeSet: unknown kind '" + name + "' (box, cylinder, sphere or convex)");
}

ShapeSet make_set(const std::vector<std::string>& kinds, const Indices& frames, const Doubles& origins,
                  const Doubles& sizes, const std::vector<std::optional<Doubles>>& vertices) {
  const auto S = static_cast<py::ssize_t>(kinds.size());
  if (frames.ndim() != 1 || frames.shape(0) != S) throw InputError("ShapeSet: frames must have shape (S,) like kinds");
  if (origins.ndim() != 3 || origins.shape(0) != S || origins.shape(1) != 4 || origins.shape(2) != 4)
    throw InputError("ShapeSet: origins must have shape (S, 4, 4)");
  if (sizes.ndim() != 2 || sizes.shape(0) != S || sizes.shape(1) != 3) throw InputError("ShapeSet: sizes must have shape (S, 3)");
  if (static_cast<py::ssize_t>(vertices.size()) != S) throw InputError("ShapeSet: vertices must have one entry per shape");
  std::vector<ConvexShape> shapes(kinds.size());
  for (py::ssize_t i = 0; i < S; ++i) {
    ConvexShape& s = shapes[static_cast<std::size_t>(i)];
    s.kind = kind_of(kinds[static_cast<std::size_t>(i)]);
    const long frame = frames.at(i);
    if (frame < 0 || frame > std::numeric_limits<int>::max()) throw InputError("ShapeSet: frames must be >= 0");
    s.frame = static_cast<int>(frame);
    s.origin.matrix() = Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(origins.data() + 16 * i);
    s.size = Eigen::Map<const Eigen::Vector3d>(sizes.data() + 3 * i);
    const auto& v = vertices[static_cast<std::size_t>(i)];
    if (s.kind == ShapeKind::Convex) {
      if (!v || v->ndim() != 2 || v->shape(1) != 3)
        throw InputError("ShapeSet: shape " + std::to_string(i) + " is convex: its vertices must have shape (V, 3)");
      s.vertices = Eigen::Map<const Eigen::Matrix<double, 3, Eigen::Dynamic>>(v->data(), 3, v->shape(0));
    } else if (v) {
      throw InputError("ShapeSet: shape " + std::to_string(i) + " is not convex: its vertices must be None");
    }
  }
  return ShapeSet(std::move(shapes));
}

// The constructor's arguments back, for pickling.
py::tuple state_of(const ShapeSet& set) {
  const auto S = static_cast<py::ssize_t>(set.size());
  py::list kinds, vertices;
  py::array_t<long> frames(S);
  py::array_t<double> origins({S, py::ssize_t{4}, py::ssize_t{4}}), sizes({S, py::ssize_t{3}});
  for (int i = 0; i < set.size(); ++i) {
    const ConvexShape& s = set.shape(i);
    kinds.append(kKindNames[static_cast<int>(s.kind)]);
    frames.mutable_at(i) = s.frame;
    Eigen::Map<Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(origins.mutable_data() + 16 * i) = s.origin.matrix();
    Eigen::Map<Eigen::Vector3d>(sizes.mutable_data() + 3 * i) = s.size;
    if (s.kind == ShapeKind::Convex) {
      py::array_t<double> v({static_cast<py::ssize_t>(s.vertices.cols()), py::ssize_t{3}});
      Eigen::Map<Eigen::Matrix<double, 3, Eigen::Dynamic>>(v.mutable_data(), 3, s.vertices.cols()) = s.vertices;
      vertices.append(v);
    } else {
      vertices.append(py::none());
    }
  }
  return py::make_tuple(kinds, frames, origins, sizes, vertices);
}

const ShapeGeometry& convex_geometry(const ShapeSet& set, long i) {
  if (i < 0 || i >= set.size()) throw InputError("ShapeSet: shape index " + std::to_string(i) + " is outside the set");
  if (set.shape(static_cast<int>(i)).kind != ShapeKind::Convex)
    throw InputError("ShapeSet: shape " + std::to_string(i) + " is not convex: it has no hull");
  return set.geometry(static_cast<int>(i));
}

struct FrameShape {
  long T, L;
};

FrameShape check_frames(const char* what, const Doubles& frames) {
  if (frames.ndim() != 4 || frames.shape(2) != 4 || frames.shape(3) != 4)
    throw InputError(std::string(what) + ": frames must have shape (T, L, 4, 4)");
  return {static_cast<long>(frames.shape(0)), static_cast<long>(frames.shape(1))};
}

long check_list(const char* what, const Indices& shapes) {
  if (shapes.ndim() != 1) throw InputError(std::string(what) + ": shapes must have shape (k,)");
  return static_cast<long>(shapes.shape(0));
}

long check_pairs(const char* what, const Indices& pairs) {
  if (pairs.ndim() != 2 || pairs.shape(1) != 2) throw InputError(std::string(what) + ": pairs must have shape (P, 2)");
  return static_cast<long>(pairs.shape(0));
}

}  // namespace

void bind_shape_set(py::module_& m) {
  py::class_<ShapeSet>(m, "ShapeSet",
                       "Convex collision shapes attached to frames (immutable; safe to share between threads)")
      .def(py::init(&make_set), py::arg("kinds"), py::arg("frames"), py::arg("origins"), py::arg("sizes"),
           py::arg("vertices"),
           "kinds: list of 'box' | 'cylinder' | 'sphere' | 'convex'; frames (S,) int: the frame each is attached "
           "to; origins (S, 4, 4): each shape's frame in its frame; sizes (S, 3): box full extents, cylinder "
           "(radius, length, 0) along its z, sphere (radius, 0, 0), unused for convex; vertices: per shape a (V, 3) "
           "array (convex, in its frame) or None")
      .def_property_readonly("size", &ShapeSet::size)
      .def_property_readonly("kinds",
                             [](const ShapeSet& set) {
                               std::vector<std::string> kinds;
                               for (int i = 0; i < set.size(); ++i)
                                 kinds.emplace_back(kKindNames[static_cast<int>(set.shape(i).kind)]);
                               return kinds;
                             })
      .def_property_readonly("frames",
                             [](const ShapeSet& set) {
                               py::array_t<long> frames(set.size());
                               for (int i = 0; i < set.size(); ++i) frames.mutable_at(i) = set.shape(i).frame;
                               return frames;
                             })
      .def_property_readonly("bounding_radii",
                             [](const ShapeSet& set) {
                               py::array_t<double> radii(set.size());
                               for (int i = 0; i < set.size(); ++i) radii.mutable_at(i) = set.geometry(i).sphere_radius;
                               return radii;
                             })
      .def(
          "hull_vertices",
          [](const ShapeSet& set, long i) {
            const Eigen::Matrix3Xd& v = convex_geometry(set, i).hull_vertices;
            py::array_t<double> out({static_cast<py::ssize_t>(v.cols()), py::ssize_t{3}});
            Eigen::Map<Eigen::Matrix<double, 3, Eigen::Dynamic>>(out.mutable_data(), 3, v.cols()) = v;
            return out;
          },
          py::arg("i"), "The convex hull's vertices (V, 3) in the shape's frame (convex shapes only)")
      .def(
          "hull_faces",
          [](const ShapeSet& set, long i) {
            const auto& faces = convex_geometry(set, i).hull_faces;
            py::array_t<long> out({static_cast<py::ssize_t>(faces.size()), py::ssize_t{3}});
            for (std::size_t f = 0; f < faces.size(); ++f)
              for (int c = 0; c < 3; ++c) out.mutable_at(f, c) = faces[f][static_cast<std::size_t>(c)];
            return out;
          },
          py::arg("i"), "The hull's triangles (F, 3), indices into hull_vertices, counter-clockwise from outside")
      .def(py::pickle(&state_of, [](const py::tuple& t) {
        if (t.size() != 5) throw InputError("ShapeSet: bad pickled state");
        return make_set(t[0].cast<std::vector<std::string>>(), t[1].cast<Indices>(), t[2].cast<Doubles>(),
                        t[3].cast<Doubles>(), t[4].cast<std::vector<std::optional<Doubles>>>());
      }));

  m.def(
      "shape_lowest_z",
      [](Doubles frames, const ShapeSet& set, Indices shapes) {
        const FrameShape f = check_frames("shape_lowest_z", frames);
        const long k = check_list("shape_lowest_z", shapes);
        py::array_t<double> out({static_cast<py::ssize_t>(f.T), static_cast<py::ssize_t>(k)});
        double* o = out.mutable_data();
        {
          py::gil_scoped_release release;
          lowest_z(frames.data(), f.T, f.L, set, shapes.data(), k, o);
        }
        return out;
      },
      py::arg("frames"), py::arg("set"), py::arg("shapes"),
      "The lowest world z of each listed shape: frames (T, L, 4, 4), shapes (k,) int -> (T, k)");
  m.def(
      "shape_lowest_points",
      [](Doubles frames, const ShapeSet& set, Indices shapes, long max_points) {
        const FrameShape f = check_frames("shape_lowest_points", frames);
        const long k = check_list("shape_lowest_points", shapes);
        if (max_points < 1) throw InputError("shape_lowest_points: max_points must be >= 1");
        py::array_t<double> out({static_cast<py::ssize_t>(f.T), static_cast<py::ssize_t>(k),
                                 static_cast<py::ssize_t>(max_points), py::ssize_t{3}});
        double* o = out.mutable_data();
        {
          py::gil_scoped_release release;
          lowest_points(frames.data(), f.T, f.L, set, shapes.data(), k, max_points, o);
        }
        return out;
      },
      py::arg("frames"), py::arg("set"), py::arg("shapes"), py::arg("max_points") = 16,
      "Each listed shape's max_points lowest ground-contact candidates in the world, by z ascending (padded with "
      "the lowest): (T, k, max_points, 3)");

  const auto pairs_call = [](const char* what, bool minimum) {
    return [what, minimum](Doubles frames_a, const ShapeSet& set_a, Doubles frames_b, const ShapeSet& set_b,
                           Indices pairs, double cutoff) {
      const FrameShape a = check_frames(what, frames_a), b = check_frames(what, frames_b);
      const long P = check_pairs(what, pairs);
      const long T = std::max(a.T, b.T);
      py::array_t<double> out = minimum ? py::array_t<double>(static_cast<py::ssize_t>(T))
                                        : py::array_t<double>({static_cast<py::ssize_t>(T), static_cast<py::ssize_t>(P)});
      double* o = out.mutable_data();
      {
        py::gil_scoped_release release;
        (minimum ? pair_min_distances : pair_distances)(frames_a.data(), a.T, a.L, set_a, frames_b.data(), b.T, b.L,
                                                        set_b, pairs.data(), P, cutoff, o);
      }
      return out;
    };
  };
  const double inf = std::numeric_limits<double>::infinity();
  m.def("shape_pair_distances", pairs_call("shape_pair_distances", false), py::arg("frames_a"), py::arg("set_a"),
        py::arg("frames_b"), py::arg("set_b"), py::arg("pairs"), py::arg("cutoff") = inf,
        "Signed distances (m) of shape pairs (P, 2) (set_a index, set_b index): frames_a (T, La, 4, 4), frames_b "
        "(T or 1, Lb, 4, 4) -> (T, P); > 0 apart, < 0 minus the penetration depth; exact where the bounding "
        "spheres' lower bound is below cutoff, that bound elsewhere");
  m.def("shape_pair_min_distances", pairs_call("shape_pair_min_distances", true), py::arg("frames_a"),
        py::arg("set_a"), py::arg("frames_b"), py::arg("set_b"), py::arg("pairs"), py::arg("cutoff") = inf,
        "The smallest of shape_pair_distances' values at each sample (pruned): (T,), +inf when there is no pair");
}

}  // namespace snakehead::bindings
