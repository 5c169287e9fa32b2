// Checks of a chain's configurations along a path, many at once and without Python in the loop: the ground
// clearance of given shapes, the self clearance of given shape pairs, the distance to obstacle shapes, each sample's
// smallest; a proof that a straight joint-space path is clear *between* its samples (the motion bound below); and the
// ZMP check of a sampled motion (paper Eqs. 25-40) with its ground clearance, in one pass.
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

#include "snakehead/dynamics.hpp"
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

// The dynamic-stability check of a sampled motion (Section 3.1, Eqs. 25-40) with contact "ground" or "footprint",
// sample for sample what snakehead.dynamics.stability.dynamic_stability computes in Python: the momenta P, L and
// the CoM (Eqs. 23, 25-31), their time derivatives by np.gradient's second-order differences (Eqs. 33-34), the ZMP
// on the ground (Eqs. 36-40; NaN where M g + dP_z/dt <= 0) and its signed distance to the convex hull of the
// contact points touching the ground (tolerance) of the first sample of each run of samples with one contact
// configuration (runs also restart every `chunk` samples, as the Python's chunks do); with the lowest z of
// `clearance_shapes` per sample.
struct ZmpCheckSpec {
  std::vector<long> contact_shapes;   // robot shapes whose lowest candidate points may touch
  long points_per_shape = 4;          // the lowest candidates of each shape (ShapeSet lowest_points)
  std::vector<long> clearance_shapes; // robot shapes whose lowest z (min over them) is reported per sample
  bool ground_key = true;             // contact "ground": the runs' key is the joints before the last touching link
  std::vector<int> key_joints;        // otherwise: these joints (the base's)
  std::vector<int> shaped_links;      // links with shapes (ground key: which touch)
  double tolerance = 1e-3;
  long chunk = 4096;
  double gravity = std::numeric_limits<double>::quiet_NaN();  // m/s^2: the caller's (model.physics.GRAVITY)
};

struct ZmpCheck {
  std::vector<double> zmp, margin, linear, angular, com, clearance;  // T x 2, T, T x 3 (three), T
  long resumed = 0;  // samples taken over from a ZmpPrefix
};

// What zmp_check computed sample by sample (momenta, CoM, clearance, the contact runs and their polygons) over the
// first samples of a motion, kept so that a later check of a motion that begins with the same samples (the lift
// from the bending state is the same for every target from a base of one shape) takes it over instead of computing
// it again. zmp_check takes it over only when the checker's model and shapes, the spec and the prefix's q and qd are
// those it was made with, bit for bit (else it computes everything). At the same origin the result is then the same
// as without it, to the bit (the per-sample values depend on their own sample only, the runs on the samples before;
// the time derivatives and the ZMP are computed over the whole motion afterwards). At an origin that differs only by
// where the base lies on the ground (the origins' z rows the same to the bit: a turn about z and a shift in x, y)
// the heights, clearances and contact runs are the same to the bit (every world frame's z row is), and the momenta,
// CoM and polygons are moved with the placement (P' = R P, c' = R c + t, L' = R L + t x P'): the same as computed
// there up to round-off (~1e-15 m; the ZMP's margins to 1e-12 m).
struct ZmpPrefix {
  const ChainModel* model = nullptr;
  const ShapeSet* shapes = nullptr;
  Eigen::Matrix4d origin = Eigen::Matrix4d::Zero();
  ZmpCheckSpec spec;
  std::vector<double> q, qd;                           // the samples it was made from (m x n each)
  std::vector<double> linear, angular, com, clearance;  // m x 3 (three), m
  std::vector<long> run;                                // m: each sample's run
  std::vector<double> vertices;                         // the runs' hull vertices (flat x, y)
  std::vector<long> start;                              // run r's vertices: start[r] .. start[r + 1] - 1
  std::vector<double> last_key;                         // the contact key of the last sample's run
  long size() const { return static_cast<long>(run.size()); }
};

// resume: a prefix to take over (when it matches, see ZmpPrefix); keep > 0: the first min(keep, T) samples' part
// is written to *kept.
ZmpCheck zmp_check(const PathChecker& checker, const RigidBodyChain& chain, const ZmpCheckSpec& spec,
                   const double* t, const double* q, const double* qd, long T, const ZmpPrefix* resume = nullptr,
                   long keep = 0, ZmpPrefix* kept = nullptr);

// The chain's masses, centres of mass, inertias, joint axes and child links for momenta / newton_euler.
RigidBodyChain chain_dynamics(const ChainModel& model);

// d/dt of x (T x m) sampled at t (T), as numpy.gradient(x, t, axis=0, edge_order=2 if T > 2 else 1).
void time_derivative(const double* t, const double* x, long T, long m, double* out);

}  // namespace snakehead
