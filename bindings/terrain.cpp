#include <pybind11/numpy.h>

#include <array>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "snakehead/model.hpp"
#include "snakehead/terrain.hpp"

namespace py = pybind11;

namespace snakehead::bindings {
namespace {

using Doubles = py::array_t<double, py::array::c_style | py::array::forcecast>;
// Indices: integers only (no forcecast, so that a float index is a TypeError rather than truncated).
using Indices = py::array_t<long, py::array::c_style>;
using Vertices = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

const char* const kKindNames[] = {"plane", "heightfield", "mesh"};

// N, the rows of an (N, columns) array; InputError naming `what` otherwise.
long rows_of(const char* what, const Doubles& a, long columns) {
  if (a.ndim() != 2 || a.shape(1) != columns)
    throw InputError(std::string("Terrain: ") + what + " must have shape (N, " + std::to_string(columns) + ")");
  return static_cast<long>(a.shape(0));
}

Eigen::Vector3d vector3(const char* what, const Doubles& a) {
  if (a.ndim() != 1 || a.shape(0) != 3) throw InputError(std::string("Terrain: ") + what + " must have shape (3,)");
  return Eigen::Map<const Eigen::Vector3d>(a.data());
}

Terrain make_heightfield(const Doubles& heights, const Doubles& size, const Doubles& origin) {
  if (heights.ndim() != 2) throw InputError("Terrain: heights must have shape (nx, ny)");
  if (size.ndim() != 1 || size.shape(0) != 2) throw InputError("Terrain: size must have shape (2,)");
  HeightfieldGrid g;
  g.nx = static_cast<long>(heights.shape(0));
  g.ny = static_cast<long>(heights.shape(1));
  g.heights.assign(heights.data(), heights.data() + heights.size());
  g.size_x = size.at(0);
  g.size_y = size.at(1);
  g.origin = vector3("origin", origin);
  py::gil_scoped_release release;
  return Terrain::heightfield(std::move(g));
}

Terrain make_mesh(const Doubles& vertices, const Indices& faces) {
  const long V = rows_of("vertices", vertices, 3);
  if (faces.ndim() != 2 || faces.shape(1) != 3) throw InputError("Terrain: faces must have shape (F, 3)");
  Vertices v = Eigen::Map<const Vertices>(vertices.data(), V, 3);
  std::vector<std::array<int, 3>> f(static_cast<std::size_t>(faces.shape(0)));
  for (std::size_t i = 0; i < f.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      const long index = faces.at(static_cast<py::ssize_t>(i), k);
      if (index < 0 || index >= V) throw InputError("Terrain: a triangle's index is outside the vertices");
      f[i][static_cast<std::size_t>(k)] = static_cast<int>(index);
    }
  py::gil_scoped_release release;
  return Terrain::mesh(std::move(v), std::move(f));
}

py::array_t<double> heights_of(const Terrain& t) {
  const HeightfieldGrid& g = t.grid();
  py::array_t<double> out({static_cast<py::ssize_t>(g.nx), static_cast<py::ssize_t>(g.ny)});
  std::copy(g.heights.begin(), g.heights.end(), out.mutable_data());
  return out;
}

py::array_t<double> vertices_of(const Terrain& t) {
  const Vertices& v = t.vertices();
  py::array_t<double> out({static_cast<py::ssize_t>(v.rows()), py::ssize_t{3}});
  Eigen::Map<Vertices>(out.mutable_data(), v.rows(), 3) = v;
  return out;
}

py::array_t<long> faces_of(const Terrain& t) {
  const auto& f = t.faces();
  py::array_t<long> out({static_cast<py::ssize_t>(f.size()), py::ssize_t{3}});
  for (std::size_t i = 0; i < f.size(); ++i)
    for (int k = 0; k < 3; ++k) out.mutable_at(i, k) = f[i][static_cast<std::size_t>(k)];
  return out;
}

py::array_t<double> copy3(const Eigen::Vector3d& v) {
  py::array_t<double> out(3);
  Eigen::Map<Eigen::Vector3d>(out.mutable_data()) = v;
  return out;
}

// The constructor's arguments back, for pickling: (kind, arrays...).
py::tuple state_of(const Terrain& t) {
  const HeightfieldGrid& g = t.grid();
  switch (t.kind()) {
    case TerrainKind::Plane: return py::make_tuple("plane", copy3(t.plane_normal()), copy3(t.plane_point()));
    case TerrainKind::Heightfield: {
      py::array_t<double> size(2);
      size.mutable_at(0) = g.size_x;
      size.mutable_at(1) = g.size_y;
      return py::make_tuple("heightfield", heights_of(t), size, copy3(g.origin));
    }
    case TerrainKind::Mesh: return py::make_tuple("mesh", vertices_of(t), faces_of(t));
  }
  throw InputError("Terrain: unknown kind");
}

Terrain from_state(const py::tuple& s) {
  const std::string kind = s.size() > 0 ? s[0].cast<std::string>() : "";
  if (kind == "plane" && s.size() == 3)
    return Terrain::plane(vector3("normal", s[1].cast<Doubles>()), vector3("point", s[2].cast<Doubles>()));
  if (kind == "heightfield" && s.size() == 4)
    return make_heightfield(s[1].cast<Doubles>(), s[2].cast<Doubles>(), s[3].cast<Doubles>());
  if (kind == "mesh" && s.size() == 3) return make_mesh(s[1].cast<Doubles>(), s[2].cast<Indices>());
  throw InputError("Terrain: bad pickled state");
}

// A query of N rows of `columns` numbers giving `per_row` numbers each, without the GIL.
template <class Call>
py::array_t<double> query(const char* what, const Doubles& in, long columns, long per_row, Call call) {
  const long n = rows_of(what, in, columns);
  py::array_t<double> out = per_row == 1 ? py::array_t<double>(static_cast<py::ssize_t>(n))
                                         : py::array_t<double>({static_cast<py::ssize_t>(n), py::ssize_t{per_row}});
  double* o = out.mutable_data();
  const double* i = in.data();
  py::gil_scoped_release release;
  call(i, n, o);
  return out;
}

void check_radii(const Doubles& radii, long n) {
  if (radii.ndim() != 1 || radii.shape(0) != n) throw InputError("Terrain: radii must have shape (N,)");
}

}  // namespace

void bind_terrain(py::module_& m) {
  py::class_<Terrain>(m, "Terrain",
                      "The ground as a surface: a plane, a heightfield (triangulated grid) or a triangle mesh "
                      "(immutable; safe to share between threads). See include/snakehead/terrain.hpp.")
      .def_static("plane", [](const Doubles& n, const Doubles& p) { return Terrain::plane(vector3("normal", n), vector3("point", p)); },
                  py::arg("normal"), py::arg("point"),
                  "A plane through point (3,) with the upward normal (3,) (any length, n_z > 0)")
      .def_static("heightfield", &make_heightfield, py::arg("heights"), py::arg("size"), py::arg("origin"),
                  "heights (nx, ny) m at x0 + i sx / (nx - 1), y0 + j sy / (ny - 1); size (sx, sy) m; origin "
                  "(x0, y0, z0) m, z0 added to every height. Each cell is split along its diagonal from (i, j) to "
                  "(i + 1, j + 1)")
      .def_static("mesh", &make_mesh, py::arg("vertices"), py::arg("faces"),
                  "A triangle surface: vertices (V, 3) m, faces (F, 3) int (its normals by the right-hand rule "
                  "point to the positive side)")
      .def_property_readonly("kind", [](const Terrain& t) { return std::string(kKindNames[static_cast<int>(t.kind())]); })
      .def_property_readonly("vertices", &vertices_of, "The surface's triangles' vertices (V, 3) (none for a plane)")
      .def_property_readonly("faces", &faces_of, "The surface's triangles (F, 3) (none for a plane)")
      .def(
          "height",
          [](const Terrain& t, const Doubles& xy) {
            return query("xy", xy, 2, 1, [&](const double* i, long n, double* o) { t.height(i, n, o); });
          },
          py::arg("xy"), "The surface's z (m) under each point (N, 2) -> (N,); NaN where there is no surface")
      .def(
          "normal",
          [](const Terrain& t, const Doubles& xy) {
            return query("xy", xy, 2, 3, [&](const double* i, long n, double* o) { t.normal(i, n, o); });
          },
          py::arg("xy"), "The unit upward normal of the facet under each point (N, 2) -> (N, 3); NaN where none")
      .def(
          "signed_distance",
          [](const Terrain& t, const Doubles& points) {
            return query("points", points, 3, 1, [&](const double* i, long n, double* o) { t.signed_distance(i, n, o); });
          },
          py::arg("points"), "Signed distance (m) of points (N, 3) to the surface, > 0 above -> (N,)")
      .def(
          "sphere_clearance",
          [](const Terrain& t, const Doubles& centres, const Doubles& radii) {
            check_radii(radii, rows_of("centres", centres, 3));
            return query("centres", centres, 3, 1,
                         [&](const double* i, long n, double* o) { t.sphere_clearance(i, radii.data(), n, o); });
          },
          py::arg("centres"), py::arg("radii"), "Spheres' signed distance minus radius: centres (N, 3), radii (N,)")
      .def(
          "capsule_clearance",
          [](const Terrain& t, const Doubles& a, const Doubles& b, const Doubles& radii) {
            const long n = rows_of("a", a, 3);
            if (rows_of("b", b, 3) != n) throw InputError("Terrain: b must have shape (N, 3) like a");
            check_radii(radii, n);
            return query("a", a, 3, 1,
                         [&](const double* i, long k, double* o) { t.capsule_clearance(i, b.data(), radii.data(), k, o); });
          },
          py::arg("a"), py::arg("b"), py::arg("radii"),
          "Capsules' clearance (m): segments a -> b (N, 3), radii (N,); see include/snakehead/terrain.hpp")
      .def(py::pickle(&state_of, &from_state));
}

}  // namespace snakehead::bindings
