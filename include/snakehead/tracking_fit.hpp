// The tracking interpolation's fit (paper Eq. 41 made to track; python/snakehead/motion/cartesian.py's
// tracking_interpolation): at every interior sample of a whole-body move, the lifted joint angles are fitted by damped
// least squares (Levenberg-Marquardt steps warm-started from the previous sample, clipped to the joint limits) to the
// interpolated points p_ij = (1 - t_j) p_si + t_j p_fi. The stacked residual of one step, in this order:
//   * points:     x_i(q) - p_ij for every tracked frame origin x_i (3 rows each);
//   * ground:     w_g (z_k(q) - c_g) for each lifted link k whose lowest point z_k is below the clearance c_g;
//   * self:       w_g (d_p(q) - c_s) for each shape pair p closer than c_s (exact signed distances; the Jacobian by
//                 forward differences of step h in each lifted joint, as the Python did);
//   * continuity: w_c (q_lift - q_lift of the previous sample), so the fit follows one branch;
// the step solves (J^T J + lambda^2 I) dq = -J^T r. A point x on link k moves with lifted joint j by a_j x (x - o_j)
// (a_j the joint's world axis, o_j its origin) when j's child link is k or before it, else not at all.
//
// Every number of the fit (weights, clearances, iterations, tolerances) comes from the caller (Python's TRACKING_*
// constants): none is defined here. A TrackingFit is immutable after construction: share it between threads freely.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <vector>

#include "snakehead/model.hpp"
#include "snakehead/shape_set.hpp"

namespace snakehead {

struct TrackingSettings {
  double damping = 0.0;          // lambda (m) of the damped least squares
  int iterations = 0;            // steps per sample at most
  double step_tolerance = 0.0;   // rad: a sample's fit stops after a step whose largest entry is below this
  double clearance = 0.0;        // c_g (m): the lifted links' lowest points are kept this high
  double ground_weight = 0.0;    // w_g: weight of the ground and self rows
  double continuity = 0.0;       // w_c (m per rad)
  double self_clearance = 0.0;   // c_s (m): the self pairs are kept this far apart
  double self_step = 0.0;        // h (rad): forward-difference step of the self distances
};

struct TrackingSpec {
  std::vector<int> lift;                        // the fitted joints (the columns of J)
  std::vector<long> points;                     // links whose frame origins track the interpolated points
  std::vector<long> lifted_links;               // links whose shapes' lowest point keeps the ground clearance
  std::vector<std::array<long, 2>> self_pairs;  // shape pairs kept self_clearance apart
};

// One damped least-squares step at a configuration: the stacked residual r, its Jacobian J (rows x lift) and the
// step dq (unclipped).
struct TrackingStep {
  Eigen::VectorXd residual;
  Eigen::MatrixXd jacobian;
  Eigen::VectorXd step;
};

class TrackingFit {
 public:
  // The model and shapes are referenced, not copied: they must outlive the fit. origin: the world pose of the chain's
  // base frame. Throws InputError on a non-finite origin or setting, iterations < 0, a lifted joint that is prismatic
  // or outside the chain, a point or lifted link outside the chain's links, a lifted link without shapes, a pair
  // outside the shape set, a shape on a frame the chain lacks.
  TrackingFit(const ChainModel& model, const ShapeSet& shapes, const Eigen::Matrix4d& origin, TrackingSpec spec,
              TrackingSettings settings);

  // Fits rows 1 .. S-2 of q (S x n, row-major) to targets (S x points x 3, row-major): each row's lifted joints start
  // from the previous row's fit (row 0's are the start) and are overwritten; the other joints and rows 0 and S-1
  // are left as given.
  void fit(double* q, long S, const double* targets) const;

  // One step at q (n) towards target (points x 3, row-major), `current` (lift) the previous sample's lifted joints.
  TrackingStep step(const Eigen::VectorXd& q, const Eigen::VectorXd& current, const double* target) const;

  int n_joints() const { return model_.n_joints(); }
  long n_points() const { return static_cast<long>(spec_.points.size()); }
  long n_lift() const { return static_cast<long>(spec_.lift.size()); }

  struct Work;  // per-call buffers (tracking_fit.cpp)

 private:
  void system(const Eigen::VectorXd& q, const Eigen::VectorXd& current, const double* target, Work& w) const;
  const ChainModel& model_;
  const ShapeSet& shapes_;
  Eigen::Isometry3d origin_;
  TrackingSpec spec_;
  TrackingSettings settings_;
  std::vector<long> child_;          // each joint's child link (its frame is the joint frame)
  std::vector<long> ground_shapes_;  // the shapes on lifted_links, in shape order
  std::vector<long> ground_owner_;   // for each of those, its position in lifted_links
  std::vector<long> self_flat_;      // spec_.self_pairs, flat (2 per pair)
};

}  // namespace snakehead
