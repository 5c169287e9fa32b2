// Convex collision shapes of a robot or a scene (boxes, cylinders, spheres, and meshes as their convex hulls),
// each attached to a frame, and the queries planning needs over many samples of those frames at once: the
// lowest point of a shape (ground clearance), its candidate ground contact points (support polygons), and
// signed distances between shapes (self-collision, obstacles), exact through FCL where they matter.
//
// Frames are given as T x L row-major 4 x 4 world poses, C-contiguous: frame l of sample t starts at
// frames[(t * L + l) * 16]. Every function here is pure: a ShapeSet may be shared by any number of threads.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <limits>
#include <memory>
#include <vector>

namespace fcl {
template <typename S>
class CollisionGeometry;
}

namespace snakehead {

enum class ShapeKind { Box, Cylinder, Sphere, Convex };

// One convex shape attached to a frame. `origin`: the shape's own frame in the frame it is attached to.
// size: Box -> full extents (x, y, z); Cylinder -> (radius, length, 0), axis along the shape frame's z, centred;
// Sphere -> (radius, 0, 0); Convex -> unused (vertices given, already scaled, in the shape frame, 3 x V).
struct ConvexShape {
  ShapeKind kind = ShapeKind::Box;
  int frame = 0;
  Eigen::Isometry3d origin = Eigen::Isometry3d::Identity();
  Eigen::Vector3d size = Eigen::Vector3d::Zero();
  Eigen::Matrix3Xd vertices;
};

// What ShapeSet derives from one shape, all in the shape's own frame.
struct ShapeGeometry {
  std::shared_ptr<const fcl::CollisionGeometry<double>> fcl;  // fcl::Box, Cylinder, Sphere or Convex
  Eigen::Vector3d sphere_centre = Eigen::Vector3d::Zero();    // bounding sphere
  double sphere_radius = 0.0;
  Eigen::Vector3d box_centre = Eigen::Vector3d::Zero();  // bounding box along the shape frame's axes (a cheap
  Eigen::Vector3d box_half = Eigen::Vector3d::Zero();    // separating-axis lower bound of distances)
  // Ground-contact candidates that do not depend on the pose: a box's 8 corners, 8 points on each rim of a
  // cylinder, a convex shape's hull vertices (a sphere has none: its lowest point depends on the pose).
  Eigen::Matrix3Xd candidates;
  // Convex only: the hull qhull made of the vertices (its vertices, triangles counter-clockwise seen from
  // outside, and each triangle's outward unit normal n and offset o: n.x <= o inside).
  Eigen::Matrix3Xd hull_vertices;
  std::vector<std::array<int, 3>> hull_faces;
  std::vector<Eigen::Vector4d> hull_planes;
};

class ShapeSet {
 public:
  // Throws InputError on a size that is not finite and > 0 where used (non-finite where unused), a non-finite
  // or non-rigid origin, frame < 0, or a Convex whose vertices are not finite or span no volume (< 4
  // non-coplanar points).
  explicit ShapeSet(std::vector<ConvexShape> shapes);

  int size() const { return static_cast<int>(shapes_.size()); }
  const ConvexShape& shape(int i) const { return shapes_.at(static_cast<std::size_t>(i)); }
  const ShapeGeometry& geometry(int i) const { return geometry_.at(static_cast<std::size_t>(i)); }
  // The largest frame index any shape uses, -1 when there is no shape.
  int max_frame() const { return max_frame_; }

 private:
  std::vector<ConvexShape> shapes_;
  std::vector<ShapeGeometry> geometry_;
  int max_frame_ = -1;
};

// Signed distance (m) of shape i of `a` at world pose pose_a (the shape's own frame in the world, i.e. its
// frame's pose times its origin) and shape j of `b` at pose_b: > 0 their separation, < 0 minus the
// penetration depth. Through FCL (libccd's GJK, EPA for penetrations; FCL's closed forms where a sphere is
// involved, see shape_set.cpp for why).
double shape_signed_distance(const ShapeSet& a, int i, const Eigen::Isometry3d& pose_a, const ShapeSet& b, int j,
                             const Eigen::Isometry3d& pose_b);

// The lowest world z of each of the k shapes `shapes` of `set` at each of T samples, in closed form:
// out (T x k). Throws InputError on a shape index outside the set, a shape's frame >= L, non-finite frames.
void lowest_z(const double* frames, long T, long L, const ShapeSet& set, const long* shapes, long k, double* out);

// Each listed shape's M lowest ground-contact candidates in the world, by z ascending: out (T x k x M x 3).
// Candidates: a box's corners; a sphere's lowest point; a cylinder's exact lowest point on each rim circle and 8
// evenly spaced points on each rim; a convex shape's hull vertices. A shape with fewer than M candidates repeats
// its lowest. M >= 1. Errors as lowest_z.
void lowest_points(const double* frames, long T, long L, const ShapeSet& set, const long* shapes, long k, long M,
                   double* out);

// Signed distances of P pairs (pairs[2p] in set_a, pairs[2p + 1] in set_b) at T = max(Ta, Tb) samples; Ta and Tb
// each T or 1 (one sample broadcast: world-fixed obstacles). out (T x P): exact (shape_signed_distance) where
// the pair's bounding spheres' lower bound |c_a - c_b| - r_a - r_b is below `cutoff`, that bound (>= cutoff)
// elsewhere. Throws InputError on indices outside the sets, frames missing, sample counts that do not
// broadcast, non-finite frames, a NaN cutoff.
void pair_distances(const double* frames_a, long Ta, long La, const ShapeSet& set_a, const double* frames_b, long Tb,
                    long Lb, const ShapeSet& set_b, const long* pairs, long P, double cutoff, double* out);

// The smallest of pair_distances' values at each sample: out (T), +infinity when P = 0. Pairs are visited by
// increasing lower bound and stop as soon as no remaining pair can be closer than the closest so far.
void pair_min_distances(const double* frames_a, long Ta, long La, const ShapeSet& set_a, const double* frames_b,
                        long Tb, long Lb, const ShapeSet& set_b, const long* pairs, long P, double cutoff,
                        double* out);

}  // namespace snakehead
