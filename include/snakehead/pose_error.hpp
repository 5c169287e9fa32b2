// The one pose-error definition used by every IK solver in snakehead and by their convergence test.
//
// The error of a pose `current` relative to a `target` is a twist expressed in the TARGET frame:
//   e = ( R_t^T (p - p_t) ,  log(R_t^T R) )            (vx vy vz wx wy wz)
// so that a per-axis tolerance refers to the target's own axes: a bound of +inf on wx leaves the roll
// about the target's x-axis free, and then wy = wz = 0 means the tip's x-axis equals the target's.
//
// Per-axis bounds act as a dead zone: the residual of axis i is sign(e_i) * max(|e_i| - b_i, 0), and a
// pose is reached when every residual is within epsilon, i.e. |e_i| <= b_i + epsilon. The dead zone
// keeps the sum of squared residuals (the SQP objective) continuously differentiable.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>
#include <limits>

namespace snakehead {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6Xd = Eigen::Matrix<double, 6, Eigen::Dynamic>;

// Rotation vector (axis * angle, angle in [0, pi]) of a rotation matrix; robust near 0 and pi.
Eigen::Vector3d rotation_log(const Eigen::Matrix3d& R);

// Inverse of the left Jacobian of SO(3) at rotation vector w: if R' = exp(d) R with small d, then
// log(R') = log(R) + Jl^{-1}(log R) d + O(|d|^2).
Eigen::Matrix3d so3_left_jacobian_inverse(const Eigen::Vector3d& w);

// e = (R_t^T (p - p_t), log(R_t^T R)) as above.
Vector6d pose_error(const Eigen::Isometry3d& target, const Eigen::Isometry3d& current);

// Dead-zone residual of an error twist: sign(e_i) * max(|e_i| - bounds_i, 0) (0 when bounds_i is inf).
Vector6d bounded_residual(const Vector6d& error, const Vector6d& bounds);

// The convergence test: every |e_i| <= bounds_i + epsilon.
bool pose_reached(const Vector6d& error, const Vector6d& bounds, double epsilon);
bool pose_reached(const Eigen::Isometry3d& target, const Eigen::Isometry3d& current, const Vector6d& bounds,
                  double epsilon);

// Residual r (bounded_residual of pose_error) and its exact derivative dr/dq (6 x n) from the geometric
// tip Jacobian `jac` (rows v; omega, base frame, point at the tip, as tip_jacobian returns it).
// Rows whose axis is inside its dead zone have a zero derivative. Returns the raw error e.
// `dr` must already have n columns (no allocation happens here).
Vector6d residual_and_jacobian(const Eigen::Isometry3d& target, const Eigen::Isometry3d& current,
                               const Matrix6Xd& jac, const Vector6d& bounds, Vector6d& r, Matrix6Xd& dr);

}  // namespace snakehead
