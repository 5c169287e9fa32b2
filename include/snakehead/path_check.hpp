// Checks of a chain's configurations along a path, many at once and without Python in the loop: the ground
// clearance of given shapes, the self clearance of given shape pairs, the distance to obstacle shapes, each sample's
// smallest; and a proof that a straight joint-space path is clear *between* its samples (the motion bound below).
// (The ZMP check of a sampled motion, on a PathChecker's chain and shapes: zmp_check.hpp.)
//
// The motion bound. Let q(s) = q_a + s (q_b - q_a), s in [0, 1], be a straight joint segment of a chain of revolute
// joints whose root frame is fixed, and p a point rigidly attached to the shape S on the link moved by joints
// 0..k_S. Then dp/ds = sum_{j <= k_S} dq_j a_j x (p - o_j) (a_j the world unit axis of joint j, o_j a point on it),
// and |a_j x (p - o_j)| is p's distance to axis j. Let c be S's bounding-sphere centre and rho its radius:
// dist(p, axis_j) <= dist(c, axis_j) + rho. In joint j's frame the axis is fixed and c moves only through the joints
// after j; the derivative of c in that frame with respect to q_i (i > j) has norm dist(c, axis_i) <= |c - o_i| <=
// reach(i, S), where reach(i, S) is the chain's arc length from o_i to c (the distances between consecutive joint
// origins and from the last to c, all constant for revolute joints). So along the segment
//     dist(c(s), axis_j(s)) <= min(dist(c, axis_j) at s = 0, at s = 1) + sum_{j < i <= k_S} |dq_i| reach(i, S)
//     and <= reach(j, S);
// call the smaller r_{j,S} (both hold for every s). Hence every point of S moves at most
//     B_S = sum_{j <= k_S} |dq_j| (r_{j,S} + rho)          per unit of s,
// i.e. any clearance f(s) built from S (its lowest z, its distance to a fixed obstacle) is B_S-Lipschitz in s.
// Ground clearance needs only z: |(a_j x (p - o_j))_z| <= |a_j,xy| dist(p, axis_j), and the axis turns by at most
// sum_{i < j} |dq_i| along the segment (rotations compose: the angle of a product is at most the sum of the angles),
// so |a_j,xy(s)| <= h_j = min(1, min(|a_j,xy| at s = 0, at s = 1) + sum_{i < j} |dq_i|) and the lowest z of S is
// Z_S = sum_j |dq_j| h_j (r_{j,S} + rho)-Lipschitz (a yaw joint's vertical axis moves nothing up or down). A pair's
// distance does not change under a common rigid motion: in the frame of the earlier link only the joints between the
// two move anything, so a self pair (S1 before S2) is sum_{k_S1 < j <= k_S2} |dq_j| (r_{j,S2} + rho_2)-Lipschitz.
// A B-Lipschitz f on [0, 1] with lower bounds l_0 <= f(0), l_1 <= f(1) has min f >= (l_0 + l_1 - B) / 2 (the two
// cones f >= l_0 - B s and f >= l_1 - B (1 - s) meet there): an interval where that is above its floor is proven
// clear. Others are split in two, down to a floor on the largest joint change, below which they are reported.
// Prismatic joints are refused (their arm lengths are not constant).
//
// A timed motion (check_motion). Nothing above needs the path to be straight: along any continuous joint path
// q(t), t in [a, b], whose joint j travels at most V_j = integral |dq_j/dt| dt (its total variation), every point
// of S moves at most sum_j V_j (r_{j,S} + rho) with r_{j,S} as above and V in place of |dq| (the instantaneous
// speed of a point of S is at most sum_j |dq_j/dt| dist(p, axis_j), and dist(c, axis_j) at any t in [a, b] is
// within sum_{i > j} V_i reach(i, S) of its value at a or b; the axis tilts at most sum_{i < j} V_i), and the cone
// bound holds with B in the arc length u(t) = sum_j integral |dq_j/dt| (r_{j,S} + rho) dt, in which f is
// 1-Lipschitz. check_motion takes the motion as the sequence of its 2 ms samples joined by straight joint segments
// (what a position-controlled joint is commanded between two control periods), so over samples a..b
// V_j = sum_{a <= k < b} |q_{k+1,j} - q_{k,j}| exactly (>= |q_{b,j} - q_{a,j}|). It evaluates the samples where a
// joint has travelled first_step since the last (in total variation), proves each interval with V, halves the
// intervals that it does not prove by sample index, and proves an unproven interval between two consecutive samples
// by halving its straight segment as check_path does.
//
// Every function is pure over immutable inputs: a PathChecker may be shared by any number of threads.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <limits>
#include <vector>

#include "snakehead/model.hpp"
#include "snakehead/shape_set.hpp"

namespace snakehead {

// What a path must keep clear of. Shape indices are into the robot's ShapeSet (frames: the chain's links) and the
// obstacles' ShapeSet (one identity frame: world shapes).
struct PathCheckSpec {
  std::vector<long> ground_shapes;                  // their lowest point must stay >= ground_floor (m)
  std::vector<std::array<long, 2>> self_pairs;      // must stay > 0 apart
  std::vector<std::array<long, 2>> obstacle_pairs;  // (robot shape, obstacle shape): must stay > 0 apart
  double ground_floor = -1e-3;
  // Per-sample obstacle minima are exact where a pair's cheap lower bound is below this (m), that bound elsewhere.
  double obstacle_cutoff = std::numeric_limits<double>::infinity();
};

// Each sample's smallest ground clearance, self clearance and obstacle distance (m); +inf where nothing is checked.
struct SampleClearances {
  std::vector<double> ground, self, obstacle;
};

struct PathOptions {
  double first_step = 0.05;        // rad: the path is first evaluated at samples at most this far apart
  double floor_step = 1e-3;        // rad: intervals are not split below this largest joint change
  bool stop_at_violation = true;   // stop at the first sample found below a floor
};

// The verdict of check_path over K waypoints (K - 1 straight segments).
struct PathVerdict {
  std::vector<unsigned char> segment_clear;  // (K - 1): 1 when every interval of the segment is proven clear
  long samples = 0;      // configurations evaluated (waypoints included)
  long proven = 0;       // intervals proven clear
  long unproven = 0;     // intervals at the floor neither proven clear nor found violated
  long violations = 0;   // evaluated samples below a floor
  double ground = std::numeric_limits<double>::infinity();    // smallest values evaluated at samples
  double self = std::numeric_limits<double>::infinity();
  double obstacle = std::numeric_limits<double>::infinity();
  bool clear() const;
};

// The verdict of check_motion over T samples.
struct MotionVerdict {
  long samples = 0, proven = 0, unproven = 0, violations = 0;  // as PathVerdict's
  double ground = std::numeric_limits<double>::infinity();      // smallest values evaluated
  double self = std::numeric_limits<double>::infinity();
  double obstacle = std::numeric_limits<double>::infinity();
  // (T): a lower bound of the smallest obstacle distance from sample k to sample k + 1 (the last: at it); <= 0 where
  // an interval is violated or unproven; +inf without obstacle pairs
  std::vector<double> obstacle_lower;
  bool clear() const { return violations == 0 && unproven == 0; }
};

class PathChecker {
 public:
  // The model, shapes and obstacles are referenced, not copied: they must outlive the checker. origin: the world
  // pose of the chain's base frame. Throws InputError on a prismatic joint, shape indices outside the sets, shapes
  // on frames the chain lacks, an obstacle set on more than one frame, a non-finite origin or floor.
  PathChecker(const ChainModel& model, const ShapeSet& shapes, const Eigen::Matrix4d& origin, PathCheckSpec spec,
              const ShapeSet* obstacles = nullptr);

  // The per-sample minima of configurations qs (T x n, row-major).
  SampleClearances sample(const double* qs, long T) const;

  // Motion bounds of the straight segment qa -> qb: B_S per robot shape (every point of S moves at most that far)
  // and Z_S (its lowest z changes at most that much), see the header's comment.
  void motion_bounds(const Eigen::VectorXd& qa, const Eigen::VectorXd& qb, std::vector<double>& B,
                     std::vector<double>& Z) const;

  // Proves the straight segments between consecutive waypoints (K x n) clear (see the header's comment).
  PathVerdict check_path(const double* waypoints, long K, const PathOptions& options) const;

  // Proves a sampled motion (T x n) clear at and between its samples (see the header's comment: the samples joined
  // by straight segments); options.first_step is the total joint travel between the first evaluated samples.
  MotionVerdict check_motion(const double* qs, long T, const PathOptions& options) const;

  const ChainModel& model() const { return model_; }
  const ShapeSet& shapes() const { return shapes_; }
  const Eigen::Isometry3d& origin() const { return origin_; }
  int n_joints() const { return model_.n_joints(); }
  long links() const { return static_cast<long>(model_.links().size()); }
  // World frames of the links at q (links() x 4 x 4 row-major) into out.
  void world_frames(const Eigen::VectorXd& q, double* out) const;
  void world_frames(const Eigen::VectorXd& q, double* out, std::vector<Eigen::Isometry3d,
                    Eigen::aligned_allocator<Eigen::Isometry3d>>& work) const;  // work: reused between calls

  enum class ItemKind { Ground, Self, Obstacle };
  struct Item {  // one checked quantity
    ItemKind kind;
    long a, b;  // robot shape; the other robot shape (Self, the later one) or obstacle shape (Obstacle)
  };
  struct Joints {  // the world axes and origins of the joints at one configuration
    std::vector<Eigen::Vector3d> axis, origin;
  };

 private:
  void measure_reach();  // joint_of_shape_ and reach_ (constant for revolute joints)
  void list_items();     // items_ from the spec, its shape indices checked
  void joints_at(const Eigen::VectorXd& q, Joints& out, std::vector<double>& frames) const;
  friend class PathProof;
  const ChainModel& model_;
  const ShapeSet& shapes_;
  const ShapeSet* obstacles_;
  Eigen::Isometry3d origin_;
  PathCheckSpec spec_;
  std::vector<int> joint_of_shape_;            // the last joint that moves each robot shape (-1: none)
  std::vector<std::vector<double>> reach_;     // reach_[S][i]: arc length from joint i's origin to S's centre
  std::vector<Item> items_;
};

// InputError unless `index` names a shape of `set` (the message names the PathChecker and `what`).
void check_shape_index(const char* what, long index, const ShapeSet& set);

}  // namespace snakehead
