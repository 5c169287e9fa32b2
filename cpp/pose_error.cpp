#include "snakehead/pose_error.hpp"

namespace snakehead {

Eigen::Vector3d rotation_log(const Eigen::Matrix3d& R) {
  // Through the unit quaternion: angle = 2 atan2(|v|, w) with w >= 0 is accurate at 0 and at pi alike.
  Eigen::Quaterniond q(R);
  q.normalize();
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  const double n = q.vec().norm();
  if (n < 1e-300) return Eigen::Vector3d::Zero();
  const double angle = 2.0 * std::atan2(n, q.w());
  return q.vec() * (angle / n);
}

Eigen::Matrix3d so3_left_jacobian_inverse(const Eigen::Vector3d& w) {
  const double theta = w.norm();
  Eigen::Matrix3d W;
  W << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
  // Jl^{-1} = I - W/2 + c W^2 with c = (1 - (theta/2) cot(theta/2)) / theta^2; series below 1e-4 rad.
  double c;
  if (theta < 1e-4) {
    c = 1.0 / 12.0 + theta * theta / 720.0;
  } else {
    const double h = 0.5 * theta;
    c = (1.0 - h * std::cos(h) / std::sin(h)) / (theta * theta);
  }
  return Eigen::Matrix3d::Identity() - 0.5 * W + c * W * W;
}

Vector6d pose_error(const Eigen::Isometry3d& target, const Eigen::Isometry3d& current) {
  const Eigen::Matrix3d Rt_T = target.linear().transpose();
  Vector6d e;
  e.head<3>() = Rt_T * (current.translation() - target.translation());
  e.tail<3>() = rotation_log(Rt_T * current.linear());
  return e;
}

Vector6d bounded_residual(const Vector6d& error, const Vector6d& bounds) {
  Vector6d r;
  for (int i = 0; i < 6; ++i) {
    const double excess = std::abs(error[i]) - bounds[i];  // -inf for an open axis
    r[i] = excess > 0 ? std::copysign(excess, error[i]) : 0.0;
  }
  return r;
}

bool pose_reached(const Vector6d& error, const Vector6d& bounds, double epsilon) {
  for (int i = 0; i < 6; ++i)
    if (!(std::abs(error[i]) <= bounds[i] + epsilon)) return false;  // NaN never counts as reached
  return true;
}

bool pose_reached(const Eigen::Isometry3d& target, const Eigen::Isometry3d& current, const Vector6d& bounds,
                  double epsilon) {
  return pose_reached(pose_error(target, current), bounds, epsilon);
}

Vector6d residual_and_jacobian(const Eigen::Isometry3d& target, const Eigen::Isometry3d& current,
                               const Matrix6Xd& jac, const Vector6d& bounds, Vector6d& r, Matrix6Xd& dr) {
  const Eigen::Matrix3d Rt_T = target.linear().transpose();
  const Vector6d e = pose_error(target, current);
  r = bounded_residual(e, bounds);
  // d(position error) = R_t^T Jv dq; the tip rotation changes by exp(R_t^T Jw dq) on the left of
  // R_t^T R, so d(log) = Jl^{-1}(log) R_t^T Jw dq. Inside the dead zone the residual is flat.
  const Eigen::Matrix3d Mrot = so3_left_jacobian_inverse(e.tail<3>()) * Rt_T;
  dr.topRows<3>().noalias() = Rt_T * jac.topRows<3>();
  dr.bottomRows<3>().noalias() = Mrot * jac.bottomRows<3>();
  for (int i = 0; i < 6; ++i)
    if (r[i] == 0.0) dr.row(i).setZero();
  return e;
}

}  // namespace snakehead
