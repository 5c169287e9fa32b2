// Reachability maps: the paper's Algorithm 1 (Section 2.2), multithreaded over voxels.
//
// 1. Sample random configurations; their tip positions form a point cloud; take its boundary: the
//    paper's boundary(P), an alpha shape chosen as MATLAB's boundary() chooses it (alpha_shape.hpp),
//    or its convex hull.
// 2. A cubic grid of side 2 * reach centred on the chain's base frame; keep the voxels whose centre
//    lies inside the boundary (or hull).
// 3. For each kept voxel, N directions spread evenly on its inscribed sphere (a Fibonacci lattice);
//    at each point a frame whose approach axis (the tip's x- or z-axis) runs from the sphere's centre
//    to the point, rolled evenly R times about that axis (or with the roll left free: one IK call
//    with the roll tolerance open); the reachability index D = 100 * solved / tried, where a point
//    counts as solved when any of its frames is (the paper's rule; or each frame counts on its own).
//    The map keeps which of them were solved (a bit per direction, or per frame), so that it can answer
//    whether a pose is reachable, not only how reachable a voxel is.
//
// Unreachable poses dominate the cost (each spends the whole IK budget), so poses that distance
// bounds prove unreachable get no IK call (ReachBound); a direction's rolled frames are first tested
// together by one IK call with the roll left free; and the voxels are swept in tiles, inside out, each
// pose's IK starting from a neighbouring voxel's solution when there is one, and getting a short
// budget where the neighbours found the direction unreachable (compute_reachability).
//
// Results are deterministic for a given seed whatever the thread count: every voxel draws its
// random numbers from its own stream (derived from the seed and the voxel's grid index), and a tile
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

// Which voxels Algorithm 1 evaluates: those inside boundary(P) (the paper's line 6; an alpha shape)
// or inside the convex hull of the cloud (this project's first releases).
enum class HullKind { Boundary, Convex };

HullKind parse_hull_kind(const std::string& s);  // "boundary" | "convex"; throws InputError
const char* hull_kind_name(HullKind h);

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
  HullKind hull = HullKind::Boundary;
  double shrink = 0.5;           // the boundary's shrink factor S in [0, 1] (MATLAB's default 0.5)
  std::uint64_t seed = 1;
  int threads = 0;               // worker threads; 0 = core_threads() (core_threads.hpp)
  int shard_index = 0;           // this run processes the in-hull voxels k with k % shard_count == shard_index
  int shard_count = 1;

  // Throws InputError naming the first bad field.
  void validate() const;
  // What the index counts per voxel ("tried"): points, or (point, roll) frames when !any_roll.
  int poses_per_voxel() const { return free_roll || any_roll ? directions : directions * rolls; }
  // The shrink factor that defines the map: S for a boundary, 0 for the convex hull (MATLAB's S = 0).
  double map_shrink() const { return hull == HullKind::Convex ? 0.0 : shrink; }
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
  // `budget` is the share of the options' timeout this call may spend (1 = all of it): the sweep gives
  // calls that start next to a solution (a neighbour's, or the same point's at another roll) less.
  virtual bool solve(const Eigen::Isometry3d& target, const Eigen::VectorXd& q_init, std::uint64_t call_seed,
                     double budget, Eigen::VectorXd& q_out) = 0;
  // The same with the roll about the approach axis left free (the sweep's test of a direction).
  // By default the fixed-roll solve: right for a stand-in whose answer does not depend on the roll.
  virtual bool solve_free_roll(const Eigen::Isometry3d& target, const Eigen::VectorXd& q_init,
                               std::uint64_t call_seed, double budget, Eigen::VectorXd& q_out) {
    return solve(target, q_init, call_seed, budget, q_out);
  }
};
using PoseSolverFactory = std::function<std::unique_ptr<PoseSolver>(const ChainModel&, const WorkspaceOptions&)>;

// The project's TRAC-IK with the options' timeout and epsilon, the roll tolerance open when free_roll.
PoseSolverFactory trac_ik_solver_factory();

// Which poses of each voxel were solved: `bytes_per_voxel` bytes per voxel, bit u of voxel v in byte
// v * bytes_per_voxel + u / 8 at bit u % 8 (numpy.unpackbits(..., bitorder="little")). Unit u is
// direction u (any roll, free roll) or frame u = direction * rolls + roll (each roll counted).
inline int reached_bytes_per_voxel(int units) { return (units + 7) / 8; }

// A computed map (or one shard of it): the in-hull voxels this run evaluated, ascending by grid index.
struct ReachabilityMap {
  WorkspaceOptions options;
  std::string chain_hash, base, tip;
  double reach = 0.0;
  VoxelGrid grid;
  std::vector<std::int64_t> voxel_ids;                                // grid linear indices
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> centres;  // m, chain base frame
  std::vector<std::int32_t> solved;                                   // poses solved per voxel
  std::vector<std::uint8_t> reached;  // which poses: see reached_bytes_per_voxel (may be empty: unknown)
  int tried = 0;                                                      // poses per voxel
  // What the map answers: kMapKindHead (the head chain's reach, Algorithm 1) or kMapKindWholeBody (the whole
  // body's stable reach, snakehead reach). A whole-body map may say with which base each pose is reached: per voxel
  // and pose, the base's flat-shape joints (base_joint_count of them) and its placement (x m, y m, yaw rad), NaN
  // where the pose is not reached; both empty when unknown.
  std::string kind = "head";
  int base_joint_count = 0;
  std::vector<double> base_joints;      // voxels x tried x base_joint_count
  std::vector<double> base_placements;  // voxels x tried x 3
  std::int64_t hull_voxels = 0;  // in-hull voxels of the whole map (all shards)
  int hull_facets = 0;           // of the convex hull, or triangles of the boundary's surface
  double alpha = 0.0;            // m, the boundary's alpha radius (infinity for the convex hull)
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
// on its own and as the algorithm states it (every frame from a random initial guess with the full
// budget; no neighbours, no free-roll test): solved[k] of options.poses_per_voxel() poses. The
// independent reference the sweep is checked against. Voxel k draws from the random stream
// stream_ids[k] (the grid index in a map). `factory` defaults to TRAC-IK.
struct VoxelEvaluation {
  std::vector<std::int32_t> solved;
  std::vector<std::uint8_t> reached;  // bits as in ReachabilityMap
  int tried = 0;
  std::int64_t ik_calls = 0, cheap_exits = 0;
  double seconds = 0.0;
  int threads_used = 0;
};
VoxelEvaluation evaluate_voxels(const ChainModel& model, const WorkspaceOptions& options,
                                const Eigen::Ref<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>& centres,
                                const std::vector<std::uint64_t>& stream_ids, const ProgressCallback& progress = nullptr,
                                const PoseSolverFactory& factory = nullptr);

// Algorithm 1 over the voxels of options' shard (tiles of neighbours, shard i of N taking every N-th
// tile). `factory` defaults to TRAC-IK.
ReachabilityMap compute_reachability(const ChainModel& model, const WorkspaceOptions& options,
                                     const ProgressCallback& progress = nullptr,
                                     const PoseSolverFactory& factory = nullptr);

// Exact union of the shards 0..N-1 of one map; throws InputError when they do not belong together.
ReachabilityMap merge_shards(const std::vector<ReachabilityMap>& shards);

// The one writer of map files (workspace_gen and Python's save both use it): an uncompressed .npz that
// numpy.load reads (keys listed in python/snakehead/workspace.py). `command` records how the map was
// made. Statistics that are not known (a map assembled elsewhere) are written as -1 (seconds: NaN).
// Throws InputError when the map is inconsistent or the file cannot be written.
void save_npz(const ReachabilityMap& map, const std::string& path, const std::string& command);
inline constexpr const char* kMapFormat = "snakehead-reachability-2";
inline constexpr const char* kMapKindHead = "head";
inline constexpr const char* kMapKindWholeBody = "whole-body";

}  // namespace snakehead
