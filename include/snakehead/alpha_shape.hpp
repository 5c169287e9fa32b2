// The paper's boundary(P): an alpha shape of the tip cloud, chosen from a shrink factor as MATLAB's
// `boundary(P, S)` chooses it (Algorithm 1, line 6; MATLAB's default S = 0.5).
//
// An alpha shape here is the union of the Delaunay tetrahedra of the points whose circumscribed
// sphere has a radius of at most alpha (a "regularised" alpha shape: tetrahedra only, as MATLAB's
// alphaShape is in 3-D). alpha = infinity gives the convex hull; smaller alphas carve concavities.
//
// How MATLAB's boundary() turns the shrink factor S in [0, 1] into alpha (read from its
// documentation and from the published boundary.m logic; the code below is our own):
//   1. the alpha spectrum: the alpha values at which the shape changes. For a regularised 3-D alpha
//      shape these are the distinct circumradii of the Delaunay tetrahedra;
//   2. the critical alpha 'one-region': the smallest alpha whose shape encloses every point and is a
//      single region (regions: tetrahedra connected through shared triangles);
//   3. the spectrum's values from the critical alpha up to the largest, in ascending order (m values):
//      alpha = value number max(ceil((1 - S) * m), 1) (1-based). S = 1 gives the tightest single
//      region, S = 0 the convex hull, S = 0.5 the median of that part of the spectrum.
#pragma once

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <vector>

namespace snakehead {

struct VoxelGrid;

class AlphaShape {
 public:
  // Delaunay triangulation (qhull) of `points` and the alpha chosen from `shrink` in [0, 1] as above.
  // Throws InputError when the points span no volume or the shrink factor is outside [0, 1].
  static AlphaShape boundary(const std::vector<Eigen::Vector3d>& points, double shrink = 0.5);

  double alpha() const { return alpha_; }                    // m, the chosen alpha radius
  double critical_alpha() const { return critical_alpha_; }  // m, the 'one-region' alpha
  double shrink() const { return shrink_; }
  std::int64_t spectrum_size() const { return spectrum_size_; }  // distinct finite circumradii
  std::int64_t n_tetrahedra() const { return static_cast<std::int64_t>(tets_.size()); }  // of the Delaunay
  std::int64_t n_solid_tetrahedra() const;  // with circumradius <= alpha
  std::int64_t n_boundary_facets() const;   // triangles of the solid's surface
  int n_regions() const;                    // face-connected regions of the solid
  double volume() const;                    // of the solid (m^3)

  // The solid contains p (inside or on one of its tetrahedra, within `tolerance` in barycentric terms).
  // Brute force over the tetrahedra: for tests and single queries.
  bool contains(const Eigen::Vector3d& p, double tolerance = 1e-12) const;
  // Linear grid indices (ascending, no repeats) of the voxels whose centre lies in the solid:
  // every solid tetrahedron tests the voxel centres of its bounding box.
  std::vector<std::int64_t> voxels_inside(const VoxelGrid& grid) const;

  // The triangulation itself (for tests): vertex indices into the input points, circumradii, and for
  // each tetrahedron its neighbours across its four faces (-1 on the convex hull).
  const std::vector<std::array<int, 4>>& tetrahedra() const { return tets_; }
  const std::vector<double>& circumradii() const { return radius_; }
  const std::vector<std::array<int, 4>>& neighbours() const { return neighbours_; }
  // The critical alpha and the chosen alpha for any shrink factor, from the same triangulation.
  double alpha_for_shrink(double shrink) const;

 private:
  bool in_solid(std::size_t t) const { return radius_[t] <= alpha_; }
  std::vector<Eigen::Vector3d> points_;
  std::vector<std::array<int, 4>> tets_;
  std::vector<std::array<int, 4>> neighbours_;
  std::vector<double> radius_;
  std::vector<double> spectrum_;  // ascending distinct finite circumradii from the critical alpha up
  double alpha_ = 0.0, critical_alpha_ = 0.0, shrink_ = 0.5;
  std::int64_t spectrum_size_ = 0;
};

}  // namespace snakehead
