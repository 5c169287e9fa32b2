// Eq. 22 of the paper: the neck joints that bring the neck's end B0 to P_d, its x-axis along r_d,
//   argmin_q |P_a - P_d|^2 + h |r_d x r_a|^2   within the joint limits,
// by a bounded Levenberg-Marquardt with the analytic Jacobian, started from the caller's joints and from the best point
// of a coarse grid (Eq. 22 is not convex). Every number comes from the caller (python/snakehead/control/neck.py).
// Free function over an immutable model: safe from many threads at once.
#pragma once

#include <Eigen/Geometry>

#include "snakehead/model.hpp"

namespace snakehead {

struct NeckFitSettings {
  double h = 0.0;                     // weight of the direction term (> 0)
  int grid_points = 0;                // per joint, evenly over [grid_fraction * lower, grid_fraction * upper]
  double grid_fraction = 0.0;
  int iterations = 0;                 // Levenberg-Marquardt steps per start, at most
  double tolerance = 0.0;             // a step that lowers the cost by less than this fraction of it ends a start
  double continuity_tolerance = 0.0;  // the grid's minimum replaces the one from q_init only when lower by this
};

struct NeckFit {
  Eigen::VectorXd q;  // the neck joints (rad)
  double cost = 0.0;  // Eq. 22's value at q (m^2)
};

// The neck chain's tip frame is B0; P0_frame is the world pose of its base frame. q_init: the first start (nullptr:
// the grid's alone), clipped to the limits. InputError for a non-finite input, settings out of range or a chain
// without joints.
NeckFit fit_neck(const ChainModel& neck, const Eigen::Isometry3d& P0_frame, const Eigen::Vector3d& P_d,
                 const Eigen::Vector3d& r_d, const NeckFitSettings& settings, const Eigen::VectorXd* q_init);

}  // namespace snakehead
