// Reachability maps: the paper's Algorithm 1 (Section 2.2), multithreaded over voxels.
//
// 1. Sample random configurations; their tip positions form a point cloud; take its convex hull.
// 2. A cubic grid of side 2 * reach centred on the chain's base frame; keep the voxels whose centre
//    lies inside the hull.
// 3. For each kept voxel, N directions spread evenly on its inscribed sphere (a Fibonacci lattice);
//    at each point a frame whose approach axis (the tip's x- or z-axis) runs from the sphere's centre
//    to the point, rolled evenly R times about that axis (or with the roll left free: one IK call
//    with the roll tolerance open); the reachability index D = 100 * solved / tried, where a point
//    counts as solved when any of its frames is (the paper's rule; or each frame counts on its own).
//
// Unreachable poses dominate the cost (each spends the whole IK budget), so poses that distance
// bounds prove unreachable get no IK call (ReachBound), and the voxels are swept in runs of
// neighbours along a grid line, each pose's IK starting from the neighbouring voxel's solution of
// the same pose when there is one (a forward and a backward pass): reachable poses are then found
// within a short budget.
//
// Results are deterministic for a given seed whatever the thread count: every voxel draws its
// random numbers from its own stream (derived from the seed and the voxel's grid index), and a run
// is solved in a fixed order by one thread, each by a seeded TRAC-IK call (a pure function of
// its inputs whose search is bounded by an evaluation budget derived from the timeout, not the clock).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "snakehead/model.hpp"

namespace snakehead {

// Which axis of the tip frame approaches the sphere's point: the head's x-axis (its direction of
// travel, the natural choice for a snake's head) or z (the paper's Table 1, as for a gripper).
enum class ApproachAxis { X, Z };

ApproachAxis parse_approach_axis(const std::string& s);  // "x" | "z"; throws InputError
const char* approach_axis_name(ApproachAxis a);

struct WorkspaceOptions {
  double voxel_size = 0.05;      // m, edge of the cubic voxels (> 0)
  int directions = 20;           // points on each voxel's inscribed sphere (>= 1)
  int rolls = 4;                 // frames about the approach axis per point (>= 1), unless free_roll
  // The paper's rule (Algorithm 1, lines 13-18): a point counts as reached when any of its rolled
  // frames is solved, and D = 100 * reached points / points. false: every (point, roll) frame counts,
  // D = 100 * solved frames / frames.
  bool any_roll = true;
  bool free_roll = false;        // one IK call per point with the roll about the approach axis free
  ApproachAxis approach = ApproachAxis::X;
  double timeout = 0.0003;       // s per IK call (> 0); seeded TRAC-IK turns it into an evaluation budget
  double epsilon = 1e-5;         // IK tolerance on the pose error (> 0)
  int cloud_samples = 50000;     // random configurations for the hull (>= 100)
  std::uint64_t seed = 1;
  int threads = 0;               // worker threads; 0 = hardware concurrency
  int shard_index = 0;           // this run processes the in-hull voxels k with k % shard_count == shard_index
  int shard_count = 1;

  // Throws InputError naming the first bad field.
  void validate() const;
  // What the index counts per voxel ("tried"): points, or (point, roll) frames when !any_roll.
  int poses_per_voxel() const { return free_roll || any_roll ? directions : directions * rolls; }
};

// A cubic grid of n x n x n voxels; voxel (i, j, l) has linear index (i * n + j) * n + l and its
// centre at origin + (i + 1/2, j + 1/2, l + 1/2) * voxel, with i along x.
struct VoxelGrid {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  // the grid's minimum corner
  double voxel = 0.0;
  int n = 0;

  // The smallest grid of voxels of the given size covering a cube of side `side` centred at `centre`.
  static VoxelGrid around(const Eigen::Vector3d& centre, double side, double voxel);
  std::int64_t count() const { return static_cast<std::int64_t>(n) * n * n; }
  double side() const { return n * voxel; }
  Eigen::Vector3d centre_of(std::int64_t k) const;
};

// A convex polytope as the intersection of half-spaces normal . x + offset <= 0 (unit outward normals).
struct ConvexHull {
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> normals;
  Eigen::VectorXd offsets;
  int n_vertices = 0;
  double volume = 0.0;

  // Qhull (libqhull_r) on a 3-D point cloud. Throws InputError if the points span no volume.
  static ConvexHull of(const std::vector<Eigen::Vector3d>& points);
  bool contains(const Eigen::Vector3d& p, double tolerance = 1e-12) const;
  int n_facets() const { return static_cast<int>(offsets.size()); }
};

// n unit vectors spread evenly over the sphere (a Fibonacci lattice).
std::vector<Eigen::Vector3d> fibonacci_directions(int n);

// A frame at `point` whose approach axis (x or z, per `axis`) is the unit vector `direction`, turned
// by `roll` rad about it; roll 0 is a fixed, deterministic choice of the other two axes.
Eigen::Isometry3d approach_frame(const Eigen::Vector3d& point, const Eigen::Vector3d& direction, double roll,
                                 ApproachAxis axis);

// Tip positions of `samples` configurations drawn uniformly within the limits (continuous joints in
// [-pi, pi]) from a stream seeded by `seed`.
std::vector<Eigen::Vector3d> sample_tip_positions(const ChainModel& model, int samples, std::uint64_t seed);

// The sweep's cheap exits: necessary conditions for a tip pose to be reachable, from distances no
// configuration of a revolute chain can change. The tip is at most reach() from the base origin;
// the last joint's origin sits at a fixed point of the tip frame, no farther from the first joint's
// origin than the sum of the distances between consecutive joint origins; the second-last joint's
// origin lies on an arc (the last joint's range) fixed in the tip frame, within the sum of the
// remaining distances of the first joint. A pose failing them is unreachable, so no IK call is
// needed. Sampled arcs get the sampling error as slack, so no reachable pose is ever rejected.
// (With a prismatic joint only the first test applies.)
class ReachBound {
 public:
  ReachBound(const ChainModel& model, const WorkspaceOptions& options);
  double reach() const { return reach_; }
  bool possible(const Eigen::Isometry3d& target) const;
  // Some roll of the frame at p with approach axis a (unit) may be reachable.
  bool possible_any_roll(const Eigen::Vector3d& p, const Eigen::Vector3d& a) const;

 private:
  bool elbow_possible(const Eigen::Isometry3d& target, double extra_slack) const;
  static constexpr int kRollSamples = 64;
  double reach_;
  ApproachAxis approach_;
  bool revolute_ = true;
  Eigen::Vector3d first_joint_, wrist_in_tip_, approach_local_ = Eigen::Vector3d::UnitX();
  double arm_ = 0.0, wrist_along_ = 0.0, wrist_radius_ = 0.0, slack_ = 0.0;
  std::vector<Eigen::Vector3d> elbow_in_tip_;
  double arm2_ = 0.0, elbow_slack_ = 0.0, roll_step_ = 0.0, roll_slack_ = 0.0;
};

// Whether one target pose is reachable. The sweep makes one per worker thread, so an implementation
// need not be thread-safe; `call_seed` makes any randomness it uses reproducible.
class PoseSolver {
 public:
  virtual ~PoseSolver() = default;
  virtual bool solve(const Eigen::Isometry3d& target, const Eigen::VectorXd& q_init, std::uint64_t call_seed,
                     Eigen::VectorXd& q_out) = 0;
};
using PoseSolverFactory = std::function<std::unique_ptr<PoseSolver>(const ChainModel&, const WorkspaceOptions&)>;

// The project's TRAC-IK with the options' timeout and epsilon, the roll tolerance open when free_roll.
PoseSolverFactory trac_ik_solver_factory();

// A computed map (or one shard of it): the in-hull voxels this run evaluated, ascending by grid index.
struct ReachabilityMap {
  WorkspaceOptions options;
  std::string chain_hash, base, tip;
  double reach = 0.0;
  VoxelGrid grid;
  std::vector<std::int64_t> voxel_ids;                                // grid linear indices
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> centres;  // m, chain base frame
  std::vector<std::int32_t> solved;                                   // poses solved per voxel
  int tried = 0;                                                      // poses per voxel
  std::int64_t hull_voxels = 0;  // in-hull voxels of the whole map (all shards)
  int hull_facets = 0;
  // Statistics of this run (not part of the map's identity).
  std::int64_t ik_calls = 0, cheap_exits = 0;  // IK calls / frames rejected by a reach bound
  double seconds = 0.0;
  int threads_used = 0;

  Eigen::VectorXd indices() const;  // 100 * solved / tried
};

// Progress: (voxels done, voxels total) from the calling thread about every 0.1 s and at the end.
// Return false to cancel: the sweep stops and throws Cancelled.
using ProgressCallback = std::function<bool(std::int64_t, std::int64_t)>;

class Cancelled : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Lines 9-21 of Algorithm 1 for voxels (spheres of diameter options.voxel_size) at any centres, each
// on its own (random initial guesses only; no runs of neighbours): solved[k] of
// options.poses_per_voxel() poses. Voxel k draws from the random stream
// stream_ids[k] (the grid index in a map). `factory` defaults to TRAC-IK.
struct VoxelEvaluation {
  std::vector<std::int32_t> solved;
  int tried = 0;
  std::int64_t ik_calls = 0, cheap_exits = 0;
  double seconds = 0.0;
  int threads_used = 0;
};
VoxelEvaluation evaluate_voxels(const ChainModel& model, const WorkspaceOptions& options,
                                const Eigen::Ref<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>& centres,
                                const std::vector<std::uint64_t>& stream_ids, const ProgressCallback& progress = nullptr,
                                const PoseSolverFactory& factory = nullptr);

// Algorithm 1 over the voxels of options' shard (runs of neighbours along z, shard i of N taking
// every N-th run). `factory` defaults to TRAC-IK.
ReachabilityMap compute_reachability(const ChainModel& model, const WorkspaceOptions& options,
                                     const ProgressCallback& progress = nullptr,
                                     const PoseSolverFactory& factory = nullptr);

// Exact union of the shards 0..N-1 of one map; throws InputError when they do not belong together.
ReachabilityMap merge_shards(const std::vector<ReachabilityMap>& shards);

// Writes the map as an uncompressed .npz that numpy.load reads (keys in python/snakehead/workspace.py).
// `command` records how the map was made. Throws InputError when the file cannot be written.
void save_npz(const ReachabilityMap& map, const std::string& path, const std::string& command);

}  // namespace snakehead
