// Newton-Euler over a snake's body chain with its root link lying still on the ground (see the Python module
// snakehead.dynamics.inverse_dynamics for the model: the weight of a link resting on the ground is carried by the
// ground, by the link's lifted share). Many samples at once; the caller gives the links' frames (from FK).
#pragma once

#include <Eigen/Core>

#include <vector>

namespace snakehead {

// The chain's constant data for newton_euler: per joint its child link and its axis (child link's frame), per link
// its mass, centre of mass (link frame) and inertia about it (link frame, row-major 3x3).
struct RigidBodyChain {
  std::vector<int> joint_child;           // n
  std::vector<Eigen::Vector3d> axis;      // n
  std::vector<double> mass;               // L
  std::vector<Eigen::Vector3d> com;       // L
  std::vector<Eigen::Matrix3d> inertia;   // L
  void validate() const;                  // throws InputError naming what is inconsistent
};

// One pass for T samples. frames: T x L x 4 x 4 (row-major) link poses in the root frame; qd, qdd: T x n;
// share: T x L lifted shares in [0, 1] (nullptr: every link's weight counts in full); gravity_root: gravity in the
// root frame (zero: inertial terms only). Out: tau (T x n) joint torques; force (T x 3) and moment (T x 3) the
// inertial wrench across the first joint, moment about the root frame's origin, root axes (the momentum rates).
void newton_euler(const RigidBodyChain& chain, const double* frames, const double* qd, const double* qdd,
                  const double* share, const Eigen::Vector3d& gravity_root, long T, long L, double* tau,
                  double* force, double* moment);

}  // namespace snakehead
