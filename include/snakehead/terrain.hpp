// The ground under the robot as a surface: a plane, a heightfield or a triangle mesh, and the queries every later
// check asks of it over many points per call: the height and the upward normal under a point, the signed distance
// of a point, and the clearance of spheres and capsules (a segment and a radius).
//
// A Terrain is immutable: every query is const and pure, so one Terrain may be shared by any number of threads.
// Arrays are C-contiguous, row-major: xy is N x 2, points N x 3.
//
// Surfaces:
// - Plane: unit normal n (n_z > 0: upward), through point p. height(x, y) = p_z - (n_x (x - p_x) + n_y (y - p_y)) / n_z;
//   signed distance n . (x - p).
// - Heightfield: heights h[i][j] (nx x ny, row-major, nx, ny >= 2) at x_i = x0 + i sx / (nx - 1),
//   y_j = y0 + j sy / (ny - 1), z = z0 + h[i][j]. Each cell [x_i, x_i+1] x [y_j, y_j+1] is split into two
//   triangles along its diagonal from (x_i, y_j) to (x_i+1, y_j+1): the surface is piecewise linear and every
//   query is exact against those triangles. Outside [x0, x0 + sx] x [y0, y0 + sy] there is no surface (height and
//   normal NaN; signed distance still measured to the nearest triangle).
// - Mesh: vertices (V x 3) and triangles (F x 3 indices): a surface, not a solid or its hull. height(x, y) is
//   the highest surface point on the vertical line through (x, y), NaN where there is none.
//
// Signed distance: the exact distance to the closest point of the surface's triangles (an axis-aligned bounding-box
// tree prunes them), positive above (heightfield, plane) or on the side the face normals point to (mesh: the
// side from which a triangle's vertices a, b, c run counter-clockwise, n = (b - a) x (c - a)). Where the closest
// point is on an edge or a vertex, the side is that of its angle-weighted pseudonormal (Baerentzen and Aanaes
// 2005), which is right for any closed or open surface whose normals agree. For a heightfield, inside its extent
// the sign is that of z - height(x, y).
#pragma once

#include <Eigen/Core>

#include <array>
#include <memory>
#include <vector>

namespace snakehead {

enum class TerrainKind { Plane, Heightfield, Mesh };

// A heightfield's grid: heights nx x ny row-major (heights[i * ny + j] at x_i, y_j), its extent (sx, sy) > 0 and
// origin (x0, y0, z0).
struct HeightfieldGrid {
  long nx = 0, ny = 0;
  std::vector<double> heights;
  double size_x = 0.0, size_y = 0.0;
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
};

class TerrainSurface;  // the triangles and their tree (cpp/terrain.cpp)

class Terrain {
 public:
  // Throws InputError on a normal that is not finite, zero or not upward (n_z <= 0 once normalised), a point not finite.
  static Terrain plane(const Eigen::Vector3d& normal, const Eigen::Vector3d& point);
  // Throws InputError on nx or ny < 2, more than limits::kMaxTerrainCells cells ((nx - 1) (ny - 1)), heights not
  // nx * ny or not finite, an extent not finite and > 0, an origin not finite.
  static Terrain heightfield(HeightfieldGrid grid);
  // Throws InputError on no triangle, more than limits::kMaxTerrainTriangles, vertices not finite, an index outside
  // the vertices, a degenerate triangle (zero area).
  static Terrain mesh(Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> vertices,
                      std::vector<std::array<int, 3>> faces);

  TerrainKind kind() const { return kind_; }
  const Eigen::Vector3d& plane_normal() const { return normal_; }  // Plane only
  const Eigen::Vector3d& plane_point() const { return point_; }    // Plane only
  const HeightfieldGrid& grid() const { return grid_; }            // Heightfield only
  // The surface's triangles (Heightfield and Mesh): vertices V x 3 and faces F x 3.
  const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>& vertices() const;
  const std::vector<std::array<int, 3>>& faces() const;

  // Each of the n points' surface z under it: out (n). NaN input gives NaN.
  void height(const double* xy, long n, double* out) const;
  // The unit upward normal (n_z >= 0) of the facet under each point: out (n x 3), NaN where there is no surface.
  void normal(const double* xy, long n, double* out) const;
  // The signed distance (m) of each point to the surface (see above): out (n).
  void signed_distance(const double* points, long n, double* out) const;
  // Spheres (centres n x 3, radii n): signed distance of the centre minus the radius.
  void sphere_clearance(const double* centres, const double* radii, long n, double* out) const;
  // Capsules (segments a -> b, each n x 3, radii n): the segment's distance to the surface minus the radius, exact
  // where the segment does not touch the surface and is on its positive side; where it touches or crosses it, the
  // smaller of 0 and its end points' signed distances, minus the radius (exact for a plane; for a heightfield or a
  // mesh an upper bound of minus the penetration depth).
  void capsule_clearance(const double* a, const double* b, const double* radii, long n, double* out) const;

 private:
  Terrain() = default;
  TerrainKind kind_ = TerrainKind::Plane;
  Eigen::Vector3d normal_ = Eigen::Vector3d::UnitZ(), point_ = Eigen::Vector3d::Zero();
  HeightfieldGrid grid_;
  std::shared_ptr<const TerrainSurface> surface_;  // Heightfield and Mesh
};

}  // namespace snakehead
