// Newton-Euler over a snake's body chain with its root link lying still on the ground (see the Python module
// snakehead.dynamics.inverse_dynamics for the model: the weight of a link resting on the ground is carried by the
// ground, by the link's lifted share). Many samples at once; the caller gives the links' frames (from FK).
#pragma once

#include <Eigen/Core>

#include <vector>

#include "snakehead/model.hpp"

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

// The chain's masses, centres of mass, inertias, joint axes and child links for momenta / newton_euler.
RigidBodyChain chain_dynamics(const ChainModel& model);

// One pass for T samples. frames: T x L x 4 x 4 (row-major) link poses in an inertial frame in which the root link
// is still (the world, or the root's own); qd, qdd: T x n; share: T x L lifted shares in [0, 1] (nullptr: every
// link's weight counts in full); gravity: gravity in that frame (zero: inertial terms only). Out: tau (T x n)
// joint torques; force (T x 3) and moment (T x 3) the inertial wrench across the first joint, moment about that
// frame's origin, in its axes (the momentum rates).
void newton_euler(const RigidBodyChain& chain, const double* frames, const double* qd, const double* qdd,
                  const double* share, const Eigen::Vector3d& gravity, long T, long L, double* tau,
                  double* force, double* moment);

// Where each link leaves the ground, for its lifted share (snakehead.dynamics.inverse_dynamics.lift_shares): the
// shaped links and, in each one's frame, the points of its shapes farthest along the body. A link's share is
// clamp(h / ramp, 0, 1), h the lowest of its points' heights; links without points have share 1.
struct LiftPoints {
  std::vector<int> link;
  std::vector<std::vector<Eigen::Vector3d>> points;
  double ramp = 0.005;
  void validate(long n_links) const;  // throws InputError naming what is inconsistent
};

// newton_euler along configurations q (T x n) without a frames array: each sample's link frames (origin times the
// chain's FK, model.links() order, the same links as chain's) are computed in place, its lifted shares from them
// (lift == nullptr: every weight in full), and its centre of mass (Eq. 23) written to com (T x 3). q is not checked.
void newton_euler_along(const ChainModel& model, const Eigen::Matrix4d& origin, const RigidBodyChain& chain,
                        const LiftPoints* lift, const double* q, const double* qd, const double* qdd,
                        const Eigen::Vector3d& gravity, long T, double* tau, double* force, double* moment,
                        double* com);

// The centre of mass (Eq. 23) of T samples, com (T x 3) = sum_k m_k (p_k + R_k c_k) / sum_k m_k, from the links'
// frames (T x L x 4 x 4, row-major), masses (L) and centres of mass in the links' frames (L x 3). Summed link by link
// in chain order, each product and sum rounded on its own (the core is built with -ffp-contract=off; no BLAS, no
// vector intrinsics): a sample's centre of mass is the same numbers whatever the samples around it, the machine or
// the number of threads. newton_euler_along's centre of mass is this one.
void center_of_mass(const double* frames, const double* masses, const double* coms, long T, long L, double* com);

// The paper's momenta (Eqs. 25-31) for T samples: linear momentum P, angular momentum L about the frames' origin,
// and the centre of mass (Eq. 23), each T x 3, from the links' frames (T x L x 4 x 4, an inertial frame in which
// the root link is still) and the joint velocities qd (T x n). Each massive link's CoM velocity is the sum over
// the joints before it of (z_i qd_i) x (c - o_i) (Eqs. 25, 27); L sums c x m c_dot and R I R^T omega (Eqs. 30-31).
void momenta(const RigidBodyChain& chain, const double* frames, const double* qd, long T, long L, double* linear,
             double* angular, double* com);

}  // namespace snakehead
