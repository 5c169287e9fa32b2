// Forward kinematics and the geometric Jacobian of a ChainModel.
//
// Free functions over an immutable model, with no allocation on the hot path beyond the outputs:
// safe to call from many threads at once. KDL's recursive solvers are the reference; these are
// tested equal to them (tests/cpp/test_kinematics.cpp).
#pragma once

#include "snakehead/model.hpp"

#include <vector>

namespace snakehead {

using Frames = std::vector<Eigen::Isometry3d, Eigen::aligned_allocator<Eigen::Isometry3d>>;
using Jacobian = Eigen::Matrix<double, 6, Eigen::Dynamic>;

// Pose of the tip in the base frame. q is not checked (use model.check_configuration first).
Eigen::Isometry3d forward_kinematics(const ChainModel& model, const Eigen::Ref<const Eigen::VectorXd>& q);

// Poses of every link of model.links() in the base frame.
void link_frames(const ChainModel& model, const Eigen::Ref<const Eigen::VectorXd>& q, Frames& out);

// Poses of every link in the frame where the chain's base frame has pose ``origin``: origin * link_frames(q), written
// row-major, 16 doubles per link, to ``out`` (room for model.links().size() of them). ``local`` is the caller's work
// buffer (the joints' world poses). q is not checked. For a rigid origin (last row 0 0 0 1) the chain is composed
// from the origin on, fixed rotations that are the identity not applied and a joint about a coordinate axis turning
// two columns only (equal to the product up to round-off; tests/cpp/test_kinematics.cpp).
void world_link_frames(const ChainModel& model, const Eigen::Matrix4d& origin, const Eigen::Ref<const Eigen::VectorXd>& q,
                       Frames& local, double* out);

// 6 x n geometric Jacobian of the tip, rows (v; omega), expressed in the base frame with the
// reference point at the tip origin (KDL's ChainJntToJacSolver convention). Also returns the tip pose.
void tip_jacobian(const ChainModel& model, const Eigen::Ref<const Eigen::VectorXd>& q, Jacobian& jac,
                  Eigen::Isometry3d& tip);

// Reference implementations through KDL's own solvers (for tests and benchmarks).
Eigen::Isometry3d kdl_forward_kinematics(const ChainModel& model, const Eigen::Ref<const Eigen::VectorXd>& q);
Jacobian kdl_jacobian(const ChainModel& model, const Eigen::Ref<const Eigen::VectorXd>& q);

}  // namespace snakehead
