// Separating-axis test of two oriented boxes (Gottschalk, Lin and Manocha, "OBBTree", SIGGRAPH 1996): the gap
// between them along the best of 15 candidate axes, in metres. Used for the body's self-collision
// (snakehead.geometry.collision.self_clearance) and for boxes against obstacles.
#pragma once

#include <Eigen/Core>

#include <limits>

namespace snakehead {

// A box in the world: centre (m), rotation (columns: the box's axes in the world), half extents (m, >= 0;
// 0 makes a face, an edge or a point).
struct OrientedBox {
  Eigen::Vector3d centre;
  Eigen::Matrix3d rotation;
  Eigen::Vector3d half_extents;
};

// The largest gap (m) between the projections of boxes a and b over the 15 candidate separating axes (the 3 + 3
// face normals and the 9 cross products of an edge of a with an edge of b), each gap divided by its axis' length
// so that it is in metres. > 0: the boxes are apart, and this is a lower bound of their distance; <= 0: they
// intersect, and minus it is the penetration depth along the best axis. Parallel edges (cross product shorter
// than 1e-9) give no axis. Worked in b's frame with C = Rb^T Ra.
// With stop_above given, the test stops as soon as some axis' gap exceeds it and returns that gap (a value
// > stop_above, not necessarily the largest): enough to take the smallest gap over many pairs.
double box_box_sat(const OrientedBox& a, const OrientedBox& b,
                   double stop_above = std::numeric_limits<double>::infinity());

// box_box_sat for P pairs of k boxes at each of T samples: centres (T x k x 3), rotations (T x k x 3 x 3, each
// row-major), half extents (k x 3, the same at every sample), pairs (P x 2 box indices), all C-contiguous.
// Writes gaps (T x P): gaps[t * P + p] is the gap of boxes pairs[p][0] and pairs[p][1] at sample t.
// Throws InputError on a pair index outside [0, k), a negative or non-finite half extent, or a non-finite
// centre or rotation. Pure: safe to call from many threads at once.
void box_pair_gaps(const double* centres, const double* rotations, const double* half_extents, const long* pairs,
                   long T, long k, long P, double* gaps);

// The smallest of those gaps at each sample: min_gaps (T), +infinity where P = 0. The same numbers as the
// minimum over box_pair_gaps' rows, faster: a pair stops being tested once it is known to be no closer than the
// closest pair so far.
void box_pair_min_gaps(const double* centres, const double* rotations, const double* half_extents,
                       const long* pairs, long T, long k, long P, double* min_gaps);

}  // namespace snakehead
