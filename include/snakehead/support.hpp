// Support polygons (paper Eq. 24) and the signed distance of a point to them (the static and ZMP margins of
// Section 3.1), for many samples at once: each sample has its own set of ground contact points.
#pragma once

#include <Eigen/Core>

#include <vector>

namespace snakehead {

// Counter-clockwise convex hull of 2-D points (Andrew's monotone chain), as indices into `points`; points on
// an edge are left out. Two indices (the extremes) for collinear points, one for coincident points, none for
// none.
std::vector<int> convex_hull(const Eigen::Ref<const Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>>& points);

// The buffers of convex_hull, for a caller that builds many hulls without allocating each time.
struct HullWork {
  std::vector<int> order, lower, upper;
};

// convex_hull into `hull` (cleared first), with the buffers of `work` (both reused between calls).
void convex_hull_into(const Eigen::Ref<const Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>>& points,
                 HullWork& work, std::vector<int>& hull);

// Signed distance of `xy` to the convex polygon of `k` vertices (k x 2, row-major) that are already a hull:
// counter-clockwise, as convex_hull gives them (rows in that order). hull_margin without building the hull again:
// > 0 inside (the distance to the nearest edge), < 0 outside; two vertices or one: minus the distance to the
// segment or point; -infinity for none.
double convex_margin(const double* vertices, long k, const Eigen::Vector2d& xy);

// Signed distance of `xy` to the convex hull of `points` (> 0 inside: the distance to the nearest edge; < 0
// outside: minus the distance to the polygon). A hull of two points or one has no inside: minus the distance
// to the segment or point. -infinity when there is no point.
double hull_margin(const Eigen::Ref<const Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>>& points,
                   const Eigen::Vector2d& xy);

// hull_margin for T samples: points (T x N x 2, row-major, sample-major), active (T x N) says which of each
// sample's N points are contacts, xy (T x 2). Returns (T).
std::vector<double> hull_margins(const double* points, const unsigned char* active, const double* xy, long T,
                                 long N);

// convex_hull for T samples (layout as hull_margins): each sample's hull vertices, counter-clockwise, as
// indices into its N points, in `vertex` (T x N, -1 after the count) and the vertex count in `count` (T).
void convex_hulls(const double* points, const unsigned char* active, long T, long N, int* vertex, int* count);


}  // namespace snakehead
