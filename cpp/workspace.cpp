#include "snakehead/workspace.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <limits>
#include <map>
#include <mutex>
#include <numeric>
#include <random>
#include <thread>

#include "snakehead/alpha_shape.hpp"
#include "snakehead/core_threads.hpp"
#include "snakehead/kinematics.hpp"
#include "snakehead/limits.hpp"
#include "snakehead/npz.hpp"
#include "snakehead/random_numbers.hpp"
#include "snakehead/trac_ik.hpp"
#include "qhull_run.hpp"

namespace snakehead {
namespace {

constexpr std::uint64_t kCloudSalt = 0xC10D;
constexpr std::uint64_t kVoxelSalt = 0x70CE1;

// Shares of the IK budget for calls that start next to a solution: from a neighbouring voxel's solution
// of the same frame (a failure falls back to the full search), and the steps of a roll continuation.
// Such a start converges in a few Newton steps when the target is reachable (about 20 kinematics
// evaluations on the default head, against ~200 for a full 0.3 ms budget), so most of the budget would
// only be spent on failures.
// Shares of the IK budget (the options' timeout) in the sweep (see evaluate_tiles). A call that starts
// from a neighbouring voxel's solution of the same frame converges in a few Newton steps when the frame
// is reachable (about 10 kinematics evaluations on the default head, against ~200 for a full 0.3 ms
// budget); one from the free-roll solution of the same point needs about 20.
constexpr double kNearBudget = 1.0 / 3.0;  // from a neighbour's solution (a failure falls back to the full search)
constexpr double kRollBudget = 0.5;        // a rolled frame from the free-roll solution
constexpr double kBriefBudget = 0.25;      // a direction the visited neighbours say is unreachable
constexpr std::uint64_t kNeighbourSalt = 0x4E1B;
// The sweep's tiles are blocks of kTileLines x kTileLines grid lines along z (part of what defines a map).
constexpr int kTileLines = 4;

class TracIKPoseSolver : public PoseSolver {
 public:
  TracIKPoseSolver(std::shared_ptr<const TracIK> ik, const WorkspaceOptions& o) : ik_(std::move(ik)) {
    opts_.timeout = o.timeout;
    opts_.epsilon = o.epsilon;
    opts_.solve_type = SolveType::Speed;
    opts_.bounds.setZero();
    free_ = opts_;
    free_.bounds[o.approach == ApproachAxis::X ? 3 : 5] = std::numeric_limits<double>::infinity();
    if (o.free_roll) opts_ = free_;
  }
  bool solve(const Eigen::Isometry3d& target, const Eigen::VectorXd& q_init, std::uint64_t call_seed, double budget,
             Eigen::VectorXd& q_out) override {
    return run(opts_, target, q_init, call_seed, budget, q_out);
  }
  bool solve_free_roll(const Eigen::Isometry3d& target, const Eigen::VectorXd& q_init, std::uint64_t call_seed,
                       double budget, Eigen::VectorXd& q_out) override {
    return run(free_, target, q_init, call_seed, budget, q_out);
  }

 private:
  bool run(const TracIKOptions& base, const Eigen::Isometry3d& target, const Eigen::VectorXd& q_init,
           std::uint64_t call_seed, double budget, Eigen::VectorXd& q_out) {
    call_ = base;
    call_.timeout = base.timeout * budget;
    call_.seed = call_seed;  // seeded TRAC-IK: a pure function of its inputs, run in this thread
    IKResult r = ik_->solve_ex(target, q_init, call_);
    if (r.found) q_out = r.q;
    return r.found;
  }
  std::shared_ptr<const TracIK> ik_;
  TracIKOptions opts_, free_, call_;
};

}  // namespace

ReachBound::ReachBound(const ChainModel& model, const WorkspaceOptions& o)
    : reach_(model.reach()), approach_(o.approach) {
  const auto& segs = model.segments();
  revolute_ = std::none_of(segs.begin(), segs.end(), [](const SegmentGeometry& s) { return s.prismatic; });
  first_joint_ = segs.front().pre.translation();
  // Distances between consecutive joint origins do not change with a revolute joint's angle (each
  // joint turns about an axis through its own origin).
  arm_ = 0.0;
  for (std::size_t k = 0; k + 1 < segs.size(); ++k) arm_ += (segs[k].post * segs[k + 1].pre).translation().norm();
  // The last joint's origin in the tip frame: T_tip = J * Motion(q) * post, and Motion fixes J's origin.
  wrist_in_tip_ = segs.back().post.inverse().translation();
  const Eigen::Vector3d a = o.approach == ApproachAxis::X ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitZ();
  wrist_along_ = wrist_in_tip_.dot(a);
  wrist_radius_ = (wrist_in_tip_ - wrist_along_ * a).norm();
  slack_ = 1e-6 + 2.0 * o.epsilon;  // never reject a pose the IK would accept within its tolerance

  // The second-last joint's origin (the "elbow") in the tip frame turns on an arc about the last
  // joint's axis as the last joint moves within its limits; sample the arc. A point of the arc lies
  // within rho * step / 2 of a sample (rho: the arc's radius), which the test adds as slack.
  const int n = static_cast<int>(segs.size());
  if (!revolute_ || n < 2) return;
  const Eigen::Isometry3d link = segs[n - 2].post * segs[n - 1].pre;  // joint n-2 frame -> joint n-1 frame
  const Eigen::Vector3d elbow = link.inverse().translation();         // elbow in the last joint's frame
  arm2_ = arm_ - link.translation().norm();
  const Eigen::Vector3d axis = segs[n - 1].axis;
  const double rho = (elbow - elbow.dot(axis) * axis).norm();
  const SamplingRange range(model);  // the last joint's range
  const double lo = range.lo[n - 1], hi = range.hi[n - 1];
  const int samples = 64;
  const double step = (hi - lo) / (samples - 1);
  const Eigen::Isometry3d post_inv = segs[n - 1].post.inverse();
  for (int k = 0; k < samples; ++k) {
    const double q = lo + step * k;
    elbow_in_tip_.push_back(post_inv * (Eigen::AngleAxisd(-q, axis) * elbow));
  }
  elbow_slack_ = rho * step / 2.0;
  // Free roll: the elbow points also turn about the approach axis through the tip; sampling the roll
  // in `roll_samples_` steps adds (distance from the axis) * roll_step / 2.
  double far = 0.0;
  for (const auto& e : elbow_in_tip_) far = std::max(far, (e - e.dot(a) * a).norm());
  roll_step_ = 2.0 * M_PI / kRollSamples;
  roll_slack_ = far * roll_step_ / 2.0;
  approach_local_ = a;
}

bool ReachBound::elbow_possible(const Eigen::Isometry3d& target, double extra_slack) const {
  if (elbow_in_tip_.empty()) return true;
  const double limit = arm2_ + slack_ + elbow_slack_ + extra_slack;
  const double limit2 = limit * limit;
  for (const auto& e : elbow_in_tip_)
    if (((target * e) - first_joint_).squaredNorm() <= limit2) return true;
  return false;
}

bool ReachBound::possible(const Eigen::Isometry3d& target) const {
  if (target.translation().norm() > reach_ + slack_) return false;
  if (!revolute_) return true;
  if (((target * wrist_in_tip_) - first_joint_).norm() > arm_ + slack_) return false;
  return elbow_possible(target, 0.0);
}

bool ReachBound::possible_any_roll(const Eigen::Vector3d& p, const Eigen::Vector3d& a) const {
  if (p.norm() > reach_ + slack_) return false;
  if (!revolute_) return true;
  // With the roll about the approach axis a free, the wrist point runs on a circle about a: take
  // the point of the circle closest to the first joint.
  const Eigen::Vector3d m = p + wrist_along_ * a;
  const Eigen::Vector3d d = first_joint_ - m;
  const double h = d.dot(a);
  const double radial = (d - h * a).norm();
  if (std::hypot(h, radial - wrist_radius_) > arm_ + slack_) return false;
  if (elbow_in_tip_.empty()) return true;
  const Eigen::Isometry3d frame = approach_frame(p, a, 0.0, approach_);
  for (int r = 0; r < kRollSamples; ++r) {
    Eigen::Isometry3d rolled = frame;
    rolled.linear() = frame.linear() * Eigen::AngleAxisd(roll_step_ * r, approach_local_).toRotationMatrix();
    if (elbow_possible(rolled, roll_slack_)) return true;
  }
  return false;
}

ApproachAxis parse_approach_axis(const std::string& s) {
  if (s == "x" || s == "X") return ApproachAxis::X;
  if (s == "z" || s == "Z") return ApproachAxis::Z;
  throw InputError("approach axis must be 'x' or 'z', got '" + s + "'");
}

const char* approach_axis_name(ApproachAxis a) { return a == ApproachAxis::X ? "x" : "z"; }

HullKind parse_hull_kind(const std::string& s) {
  if (s == "boundary") return HullKind::Boundary;
  if (s == "convex") return HullKind::Convex;
  throw InputError("hull must be 'boundary' or 'convex', got '" + s + "'");
}

const char* hull_kind_name(HullKind h) { return h == HullKind::Boundary ? "boundary" : "convex"; }

void WorkspaceOptions::validate() const {
  // Upper limits (limits.hpp) keep every buffer a sweep allocates, and the clock deadline of each IK call,
  // within reach: a number beyond one is a mistake, reported before any work.
  auto count_in = [](const char* field, long long value, long long least, long long most, const char* hint = "") {
    if (value < least || value > most)
      throw InputError(std::string(field) + " must be between " + std::to_string(least) + " and " +
                       std::to_string(most) + hint + ", got " + std::to_string(value));
  };
  if (!(std::isfinite(voxel_size) && voxel_size > 0))
    throw InputError("voxel size must be a positive number of metres, got " + number_text(voxel_size));
  count_in("directions", directions, 1, limits::kMaxDirections);
  if (!free_roll) {
    count_in("rolls", rolls, 1, limits::kMaxRolls, " (or use free roll)");
    count_in("directions x rolls (frames per voxel)", static_cast<long long>(directions) * rolls, 1,
             limits::kMaxFramesPerVoxel);
  }
  check_timeout(timeout, "timeout");
  if (!(std::isfinite(epsilon) && epsilon > 0))
    throw InputError("epsilon must be positive, got " + number_text(epsilon));
  count_in("cloud_samples", cloud_samples, 100, limits::kMaxCloudSamples, " (the hull needs a cloud)");
  if (!(shrink >= 0.0 && shrink <= 1.0))
    throw InputError("shrink (the boundary's shrink factor) must be within [0, 1], got " + number_text(shrink));
  count_in("threads", threads, 0, limits::kMaxThreads, " (0 = all cores)");
  if (shard_count < 1 || shard_index < 0 || shard_index >= shard_count)
    throw InputError("shard must be i/N with 0 <= i < N, got " + std::to_string(shard_index) + "/" +
                     std::to_string(shard_count));
}

VoxelGrid VoxelGrid::around(const Eigen::Vector3d& centre, double side, double voxel) {
  if (!(std::isfinite(voxel) && voxel > 0)) throw InputError("voxel size must be positive");
  if (!(std::isfinite(side) && side > 0)) throw InputError("grid side must be positive");
  const double cells = std::ceil(side / voxel - 1e-9);
  if (!(cells <= limits::kMaxVoxelsPerAxis))
    throw InputError("voxel size " + number_text(voxel) + " m is too small for the grid of side " + number_text(side) +
                     " m: " + number_text(cells) + " voxels per axis, at most " +
                     std::to_string(limits::kMaxVoxelsPerAxis) + " (voxel size >= " +
                     number_text(side / limits::kMaxVoxelsPerAxis) + " m)");
  VoxelGrid g;
  g.n = std::max(1, static_cast<int>(cells));
  g.voxel = voxel;
  g.origin = centre - Eigen::Vector3d::Constant(0.5 * g.n * voxel);
  return g;
}

Eigen::Vector3d VoxelGrid::centre_of(std::int64_t k) const {
  const std::int64_t l = k % n, j = (k / n) % n, i = k / (static_cast<std::int64_t>(n) * n);
  return origin + voxel * Eigen::Vector3d(i + 0.5, j + 0.5, l + 0.5);
}

ConvexHull ConvexHull::of(const std::vector<Eigen::Vector3d>& points) {
  if (points.size() < 4) throw InputError("a convex hull in 3-D needs at least 4 points");
  QhullRun run(points, "qhull Qt");  // Qt: triangulated output (simplicial facets, planes as computed)
  qhT* qh = run.qh;
  ConvexHull hull;
  if (run.ok()) {
    std::vector<Eigen::Vector3d> normals;
    std::vector<double> offsets;
    facetT* facet;
    FORALLfacets {
      normals.emplace_back(facet->normal[0], facet->normal[1], facet->normal[2]);
      offsets.push_back(facet->offset);
    }
    hull.normals.resize(static_cast<Eigen::Index>(normals.size()), 3);
    hull.offsets.resize(static_cast<Eigen::Index>(offsets.size()));
    for (std::size_t k = 0; k < normals.size(); ++k) {
      hull.normals.row(static_cast<Eigen::Index>(k)) = normals[k].transpose();
      hull.offsets[static_cast<Eigen::Index>(k)] = offsets[k];
    }
    hull.n_vertices = qh->num_vertices;
    qh_getarea(qh, qh->facet_list);
    hull.volume = qh->totvol;
  }
  if (!run.ok())
    throw InputError("the tip's point cloud spans no volume, so it has no convex hull (qhull: " + run.error() + ")");
  return hull;
}

bool ConvexHull::contains(const Eigen::Vector3d& p, double tolerance) const {
  if (offsets.size() == 0) return false;
  return ((normals * p + offsets).array() <= tolerance).all();
}

std::vector<Eigen::Vector3d> fibonacci_directions(int n) {
  if (n < 1 || n > limits::kMaxDirections)
    throw InputError("directions must be between 1 and " + std::to_string(limits::kMaxDirections) + ", got " +
                     std::to_string(n));
  // Points at equal-area heights z_k = 1 - (2k + 1) / n, turned by the golden angle each step.
  const double golden_angle = M_PI * (3.0 - std::sqrt(5.0));
  std::vector<Eigen::Vector3d> d(n);
  for (int k = 0; k < n; ++k) {
    const double z = 1.0 - (2.0 * k + 1.0) / n;
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const double phi = golden_angle * k;
    d[k] = Eigen::Vector3d(r * std::cos(phi), r * std::sin(phi), z);
  }
  return d;
}

Eigen::Isometry3d approach_frame(const Eigen::Vector3d& point, const Eigen::Vector3d& direction, double roll,
                                 ApproachAxis axis) {
  const double norm = direction.norm();
  if (!(std::isfinite(norm) && norm > 0)) throw InputError("approach direction must be a finite non-zero vector");
  if (!point.allFinite() || !std::isfinite(roll)) throw InputError("approach frame point and roll must be finite");
  const Eigen::Vector3d a = direction / norm;
  // Roll 0: the first tangent axis is the world axis least aligned with a, made perpendicular to it.
  Eigen::Index least;
  a.cwiseAbs().minCoeff(&least);
  Eigen::Vector3d u = Eigen::Vector3d::Unit(least) - a[least] * a;
  u.normalize();
  const Eigen::Vector3d v = a.cross(u);
  const Eigen::Vector3d t = std::cos(roll) * u + std::sin(roll) * v;
  Eigen::Isometry3d f = Eigen::Isometry3d::Identity();
  if (axis == ApproachAxis::X) {
    f.linear().col(0) = a;  // x = a, y = t, z = x cross y
    f.linear().col(1) = t;
    f.linear().col(2) = a.cross(t);
  } else {
    f.linear().col(2) = a;  // z = a, x = t, y = z cross x
    f.linear().col(0) = t;
    f.linear().col(1) = a.cross(t);
  }
  f.translation() = point;
  return f;
}

std::vector<Eigen::Vector3d> sample_tip_positions(const ChainModel& model, int samples, std::uint64_t seed) {
  if (samples < 1 || samples > limits::kMaxCloudSamples)
    throw InputError("samples must be between 1 and " + std::to_string(limits::kMaxCloudSamples) + ", got " +
                     std::to_string(samples));
  std::mt19937_64 rng(stream_seed(seed, kCloudSalt, 0));
  const SamplingRange range(model);
  std::vector<Eigen::Vector3d> pts(samples);
  Eigen::VectorXd q;
  for (int k = 0; k < samples; ++k) {
    range.draw(rng, q);
    pts[k] = forward_kinematics(model, q).translation();
  }
  return pts;
}

PoseSolverFactory trac_ik_solver_factory() {
  return [](const ChainModel& model, const WorkspaceOptions& o) -> std::unique_ptr<PoseSolver> {
    TracIKOptions t;
    t.timeout = o.timeout;
    t.epsilon = o.epsilon;
    auto ik = std::make_shared<const TracIK>(model, t);
    return std::make_unique<TracIKPoseSolver>(std::move(ik), o);
  };
}

Eigen::VectorXd ReachabilityMap::indices() const {
  Eigen::VectorXd d(static_cast<Eigen::Index>(solved.size()));
  for (std::size_t k = 0; k < solved.size(); ++k)
    d[static_cast<Eigen::Index>(k)] = tried > 0 ? 100.0 * solved[k] / tried : 0.0;
  return d;
}

namespace {

// A tile: voxels computed together by one thread, each starting from its neighbours' results.
// `rows` index the centres in the order they are visited; `neighbours[k]` lists, for the k-th visited
// voxel, the positions in `rows` of its neighbours in the tile (face neighbours first).
struct Tile {
  std::vector<std::int64_t> rows;
  std::vector<std::vector<int>> neighbours;
};

// The sweep's strategy (see evaluate_tiles). Plain: every frame from random guesses with the full
// budget, as Algorithm 1 states it (the independent reference of evaluate_voxels).
enum class Strategy { Plain, Neighbours };

VoxelEvaluation evaluate_tiles(const ChainModel& model, const WorkspaceOptions& options,
                               const Eigen::Ref<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>& centres,
                               const std::vector<std::uint64_t>& stream_ids, const std::vector<Tile>& tiles,
                               Strategy strategy, const ProgressCallback& progress, const PoseSolverFactory& factory_in) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto total = static_cast<std::int64_t>(centres.rows());
  if (static_cast<std::int64_t>(stream_ids.size()) != total)
    throw InputError("one stream id per voxel centre is needed");
  if (!centres.allFinite()) throw InputError("voxel centres must be finite");
  const PoseSolverFactory factory = factory_in ? factory_in : trac_ik_solver_factory();

  VoxelEvaluation out;
  out.tried = options.poses_per_voxel();
  out.solved.assign(total, 0);
  const int bytes_per_voxel = reached_bytes_per_voxel(out.tried);
  out.reached.assign(static_cast<std::size_t>(total) * bytes_per_voxel, 0);
  const std::vector<Eigen::Vector3d> dirs = fibonacci_directions(options.directions);
  const int n_rolls = options.free_roll ? 1 : options.rolls;
  const ReachBound bound(model, options);
  const SamplingRange range(model);
  const double radius = 0.5 * options.voxel_size;
  int n_threads = options.threads > 0 ? options.threads : core_threads();
  n_threads = static_cast<int>(
      std::max<std::int64_t>(1, std::min<std::int64_t>(std::max(n_threads, 1), static_cast<std::int64_t>(tiles.size()))));
  out.threads_used = n_threads;
  // Solvers are made here, so that a bad option fails before any thread starts.
  std::vector<std::unique_ptr<PoseSolver>> solvers;
  for (int t = 0; t < n_threads; ++t) solvers.push_back(factory(model, options));

  std::atomic<std::int64_t> next{0}, done{0}, ik_calls{0}, cheap{0};
  std::atomic<bool> stop{false};
  std::mutex mutex;
  std::condition_variable cv;
  std::exception_ptr failure;

  // One task is one tile, computed start to finish by one thread in a fixed order: the result does not
  // depend on the thread count. Dynamic scheduling (an atomic counter) balances tiles of different cost.
  //
  // A voxel's "units" are what the index counts: its directions when any roll will do (the paper's
  // rule, and free roll), else its (direction, roll) frames. A unit is reached when one of its
  // candidate frames is solved. Frame c of a voxel is frame c of its neighbour moved by one voxel, so
  // a neighbour's solution is an excellent initial guess (a few Newton steps away when reachable).
  //
  // Unreachable frames dominate the cost: each spends the whole IK budget. Three things make them cheap:
  // - a direction's rolled frames are not tried one by one from random guesses: one IK call with the
  //   roll left free (a relaxation: it solves whenever one of the rolled frames can be solved) decides
  //   first. When it fails, the direction is unreached without a call per roll; when it succeeds, the
  //   rolled frames are tried from its solution, nearest roll first;
  // - a voxel whose visited neighbours include one that failed a direction with the full budget, and
  //   none that reached it, tests that direction with a short budget (unreachable regions are wide);
  // - calls that start from a neighbour's solution get a short budget (reachable ones converge fast).
  // What a short budget misses is recovered by propagation: a unit still unreached whose neighbour
  // reached it is tried again from that neighbour's solution, until nothing changes.
  const int n_dirs = options.directions;
  const int per_unit = options.free_roll || !options.any_roll ? 1 : options.rolls;  // candidate frames
  const int units = options.poses_per_voxel();
  const int frames_per_voxel = n_dirs * n_rolls;
  // The free-roll test pays when it can replace more than one fixed-roll call per direction.
  const bool probe_directions = strategy == Strategy::Neighbours && !options.free_roll && n_rolls > 1;
  const bool neighbours_help = strategy == Strategy::Neighbours;
  auto work = [&](PoseSolver& solver) {
    std::int64_t my_calls = 0, my_cheap = 0;
    Eigen::VectorXd q_out(model.n_joints());
    std::vector<Eigen::Isometry3d, Eigen::aligned_allocator<Eigen::Isometry3d>> targets;
    std::vector<char> possible, probe_possible;
    // Per (voxel, direction) of the free-roll test, and per unit of what decides it without neighbours:
    // 0 not tried, 1 solved, -1 failed with the full budget, -2 failed with a short one.
    std::vector<signed char> probe_state, dir_state, no_roll;
    std::vector<double> probe_roll;  // the roll of the free-roll solution (rad)
    std::vector<int> reached_by;     // per unit: the candidate that reached it, or -1
    std::vector<std::uint32_t> tried_from;  // per unit: neighbours (bit = position in the list) tried from
    std::vector<Eigen::VectorXd> solutions, guesses, probe_q;
    std::vector<std::uint64_t> seeds, probe_seeds;
    std::vector<int> order(n_rolls);
    auto attempt = [&](std::int64_t unit, int c, const Eigen::VectorXd& q_init, std::uint64_t seed, double budget) {
      const std::int64_t f = unit * per_unit + c;
      if (!possible[f]) return false;
      ++my_calls;
      if (!solver.solve(targets[f], q_init, seed, budget, q_out)) return false;
      reached_by[unit] = c;
      solutions[unit] = q_out;
      return true;
    };
    // Whether the visited neighbours of voxel `a` (tile position) say that direction `di` is unreachable:
    // one failed it with the full budget and none reached it.
    auto looks_unreachable = [&](const Tile& tile, int a, int di, const std::vector<char>& visited) {
      if (!neighbours_help) return false;
      bool full_failure = false;
      for (int b : tile.neighbours[a]) {
        if (!visited[b]) continue;
        const signed char s = dir_state[static_cast<std::size_t>(b) * n_dirs + di];
        if (s > 0) return false;
        full_failure |= s == -1;
      }
      return full_failure;
    };
    // The free-roll test of direction `di` of the voxel at tile position `a`.
    auto probe = [&](const Tile& tile, int a, int di, const std::vector<char>& visited) {
      const std::int64_t dir = static_cast<std::int64_t>(a) * n_dirs + di;
      if (probe_state[dir] != 0) return probe_state[dir] > 0;
      probe_state[dir] = -1;
      const std::int64_t f0 = dir * n_rolls;  // the roll-0 frame of the direction
      if (!probe_possible[dir]) return false;
      const bool brief = looks_unreachable(tile, a, di, visited);
      // Start from a visited neighbour's free-roll solution of the same direction, else from a random guess.
      const Eigen::VectorXd* start = &guesses[f0];
      for (int b : tile.neighbours[a])
        if (visited[b] && probe_state[static_cast<std::size_t>(b) * n_dirs + di] > 0) {
          start = &probe_q[static_cast<std::size_t>(b) * n_dirs + di];
          break;
        }
      ++my_calls;
      if (!solver.solve_free_roll(targets[f0], *start, probe_seeds[dir], brief ? kBriefBudget : 1.0, q_out)) {
        probe_state[dir] = dir_state[dir] = brief ? -2 : -1;
        return false;
      }
      probe_state[dir] = dir_state[dir] = 1;
      probe_q[dir] = q_out;
      // Roll of the solution about the approach axis, relative to the roll-0 frame.
      const Eigen::Matrix3d rel = targets[f0].linear().transpose() * forward_kinematics(model, q_out).linear();
      probe_roll[dir] = options.approach == ApproachAxis::X ? std::atan2(rel(2, 1), rel(1, 1))
                                                             : std::atan2(rel(1, 0), rel(0, 0));
      return true;
    };
    try {
      for (std::int64_t t = next++; t < static_cast<std::int64_t>(tiles.size()) && !stop.load(std::memory_order_relaxed);
           t = next++) {
        const Tile& tile = tiles[t];
        const auto n_vox = static_cast<std::int64_t>(tile.rows.size());
        const std::int64_t n_frames = n_vox * frames_per_voxel;
        const std::int64_t n_directions = n_vox * n_dirs;
        targets.resize(n_frames);
        possible.assign(n_frames, 0);
        guesses.resize(n_frames);
        seeds.resize(n_frames);
        probe_possible.assign(n_directions, 0);
        probe_state.assign(n_directions, 0);
        probe_roll.assign(n_directions, 0.0);
        probe_q.resize(n_directions);
        probe_seeds.resize(n_directions);
        reached_by.assign(n_vox * units, -1);
        dir_state.assign(n_directions, 0);
        no_roll.assign(n_directions, 0);
        tried_from.assign(n_vox * units, 0);
        solutions.resize(n_vox * units);
        std::vector<char> visited(n_vox, 0);
        // Lines 11-15: the frames of every voxel of the tile (frame index = (voxel, direction, roll)),
        // the cheap exits, and each frame's random guess and IK seed from the voxel's own stream.
        for (std::int64_t a = 0; a < n_vox; ++a) {
          const std::int64_t row = tile.rows[a];
          const Eigen::Vector3d c = centres.row(row).transpose();
          std::mt19937_64 rng(stream_seed(options.seed, kVoxelSalt, stream_ids[row]));
          // The whole sphere beyond the tip's reach: index 0 without looking at a single frame.
          const bool in_reach = c.norm() - radius <= bound.reach() + 1e-9;
          for (int di = 0; di < n_dirs; ++di) {
            const Eigen::Vector3d& d = dirs[di];
            const Eigen::Vector3d p = c + radius * d;
            const std::int64_t dir = a * n_dirs + di;
            probe_possible[dir] = in_reach && bound.possible_any_roll(p, d);
            for (int r = 0; r < n_rolls; ++r) {
              const std::int64_t f = dir * n_rolls + r;
              targets[f] = approach_frame(p, d, 2.0 * M_PI * r / n_rolls, options.approach);
              possible[f] = in_reach && (options.free_roll ? probe_possible[dir] : bound.possible(targets[f]));
              my_cheap += !possible[f];
              range.draw(rng, guesses[f]);
              seeds[f] = rng();
            }
          }
          for (int di = 0; di < n_dirs; ++di) probe_seeds[a * n_dirs + di] = rng();
        }
        // The rolled frames of a direction in the order to try them: nearest the free-roll solution's first.
        auto roll_order = [&](std::int64_t dir) {
          std::iota(order.begin(), order.end(), 0);
          const double psi = probe_roll[dir];
          auto gap = [&](int r) { return std::abs(std::remainder(2.0 * M_PI * r / n_rolls - psi, 2.0 * M_PI)); };
          std::stable_sort(order.begin(), order.end(), [&](int x, int y) { return gap(x) < gap(y); });
        };
        // Tries unit u of voxel a from the solutions of its neighbours that reached it (each at most once).
        auto from_neighbours = [&](int a, int u, int most, bool later_only) {
          const std::int64_t unit = static_cast<std::int64_t>(a) * units + u;
          const auto& nb = tile.neighbours[a];
          for (std::size_t k = 0; k < nb.size() && k < 32 && most > 0; ++k) {
            const std::int64_t other = static_cast<std::int64_t>(nb[k]) * units + u;
            if ((later_only && nb[k] < a) || reached_by[other] < 0 || (tried_from[unit] >> k) & 1U) continue;
            tried_from[unit] |= 1U << k;
            --most;
            const int c = reached_by[other];
            if (attempt(unit, c, solutions[other], splitmix64(seeds[unit * per_unit + c] ^ (kNeighbourSalt + k)),
                        kNearBudget))
              return true;
          }
          return false;
        };
        // First visit of every voxel, in the tile's order.
        for (int a = 0; a < static_cast<int>(n_vox); ++a) {
          for (int u = 0; u < units; ++u) {
            const std::int64_t unit = static_cast<std::int64_t>(a) * units + u;
            if (neighbours_help && from_neighbours(a, u, 1, false)) {
              dir_state[static_cast<std::size_t>(a) * n_dirs + (options.any_roll || options.free_roll ? u : u / n_rolls)] = 1;
              continue;
            }
            if (!probe_directions) {
              // Each candidate frame from its random guess (short budget where the neighbours say unreachable).
              const int di = options.any_roll || options.free_roll ? u : u / n_rolls;
              const bool brief = looks_unreachable(tile, a, di, visited);
              for (int c = 0; c < per_unit; ++c) {
                const std::int64_t f = unit * per_unit + c;
                if (attempt(unit, c, guesses[f], seeds[f], brief ? kBriefBudget : 1.0)) break;
              }
              signed char& state = dir_state[static_cast<std::size_t>(a) * n_dirs + di];
              if (reached_by[unit] >= 0) state = 1;
              else if (state == 0) state = brief ? -2 : -1;
              continue;
            }
            // Directions: unit u is direction u (any roll) or frame u of direction u / n_rolls (each roll).
            const int di = options.any_roll ? u : u / n_rolls;
            const std::int64_t dir = static_cast<std::int64_t>(a) * n_dirs + di;
            if (!probe(tile, a, di, visited)) continue;
            if (options.any_roll) {
              roll_order(dir);
              // Where a visited neighbour solved this direction with its roll free but at none of the rolls,
              // and no visited neighbour reached it, only the nearest roll is tried.
              bool rollless = false;
              for (int b : tile.neighbours[a]) {
                if (!visited[b]) continue;
                if (reached_by[static_cast<std::int64_t>(b) * units + u] >= 0) {
                  rollless = false;
                  break;
                }
                rollless |= no_roll[static_cast<std::size_t>(b) * n_dirs + di] != 0;
              }
              int tried = 0;
              for (int k = 0; k < n_rolls && tried < (rollless ? 1 : n_rolls); ++k) {
                const int c = order[k];
                if (!possible[unit * per_unit + c]) continue;
                ++tried;
                if (attempt(unit, c, probe_q[dir], seeds[unit * per_unit + c], kRollBudget)) break;
              }
              if (tried > 0 && reached_by[unit] < 0) no_roll[dir] = 1;
            } else {
              attempt(unit, 0, probe_q[dir], seeds[unit], kRollBudget);
            }
          }
          visited[a] = 1;
        }
        // Second chances, in reverse order: units still unreached are tried from a neighbour visited
        // after them that reached them.
        if (neighbours_help)
          for (int a = static_cast<int>(n_vox) - 1; a >= 0; --a)
            for (int u = 0; u < units; ++u)
              if (reached_by[static_cast<std::int64_t>(a) * units + u] < 0) from_neighbours(a, u, 1, true);
        for (std::int64_t a = 0; a < n_vox; ++a) {
          int count = 0;
          std::uint8_t* bits = &out.reached[static_cast<std::size_t>(tile.rows[a]) * bytes_per_voxel];
          for (int u = 0; u < units; ++u) {
            if (reached_by[a * units + u] < 0) continue;
            ++count;
            bits[u / 8] |= static_cast<std::uint8_t>(1U << (u % 8));
          }
          out.solved[tile.rows[a]] = count;
        }
        if ((done += n_vox) == total) cv.notify_all();
      }
    } catch (...) {
      std::lock_guard<std::mutex> lock(mutex);
      if (!failure) failure = std::current_exception();
      stop = true;
      cv.notify_all();
    }
    ik_calls += my_calls;
    cheap += my_cheap;
  };

  std::vector<std::thread> pool;
  pool.reserve(n_threads);
  for (int t = 0; t < n_threads; ++t) pool.emplace_back(work, std::ref(*solvers[t]));
  bool cancelled = false;
  {
    std::unique_lock<std::mutex> lock(mutex);
    while (done.load() < total && !stop.load()) {
      cv.wait_for(lock, std::chrono::milliseconds(100));
      if (progress && !stop.load()) {
        lock.unlock();
        bool go_on = false;
        try {
          go_on = progress(done.load(), total);
        } catch (...) {
          // The callback's own exception (e.g. Python's KeyboardInterrupt) wins over Cancelled.
          lock.lock();
          if (!failure) failure = std::current_exception();
          stop = true;
          break;
        }
        lock.lock();
        if (!go_on) {
          cancelled = true;
          stop = true;
        }
      }
    }
  }
  for (auto& th : pool) th.join();
  if (failure) std::rethrow_exception(failure);
  if (cancelled) throw Cancelled("workspace sweep cancelled");
  if (progress) progress(done.load(), total);

  out.ik_calls = ik_calls.load();
  out.cheap_exits = cheap.load();
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}


// The grid voxels whose centre lies inside a convex hull, ascending. The hull cuts a z-line in one
// interval: bound it from the facet planes first, so that only a few voxels per line need the full
// test (a grid of n^3 voxels costs n^2 * facets, not n^3 * facets).
std::vector<std::int64_t> convex_voxels(const ConvexHull& hull, const VoxelGrid& grid) {
  std::vector<std::int64_t> ids;
  const int n = grid.n;
  const double h = grid.voxel;
  for (std::int64_t line = 0; line < static_cast<std::int64_t>(n) * n; ++line) {
    const Eigen::Vector3d c0 = grid.centre_of(line * n);
    double zlo = -std::numeric_limits<double>::infinity(), zhi = std::numeric_limits<double>::infinity();
    for (int f = 0; f < hull.n_facets() && zlo <= zhi; ++f) {
      const double nz = hull.normals(f, 2);
      const double rest = hull.normals(f, 0) * c0.x() + hull.normals(f, 1) * c0.y() + hull.offsets[f];
      if (std::abs(nz) < 1e-12) {
        if (rest > 1e-9) zlo = std::numeric_limits<double>::infinity();  // the line misses this facet's half-space
      } else if (nz > 0) {
        zhi = std::min(zhi, -rest / nz);
      } else {
        zlo = std::max(zlo, -rest / nz);
      }
    }
    if (!(zlo <= zhi)) continue;
    const int l_first = static_cast<int>(std::max(0.0, std::floor((zlo - grid.origin.z()) / h - 0.5) - 1));
    const int l_last = static_cast<int>(std::min(n - 1.0, std::ceil((zhi - grid.origin.z()) / h - 0.5) + 1));
    for (int l = l_first; l <= l_last; ++l) {
      const std::int64_t k = line * n + l;
      if (hull.contains(grid.centre_of(k))) ids.push_back(k);
    }
  }
  return ids;
}
}  // namespace

VoxelEvaluation evaluate_voxels(const ChainModel& model, const WorkspaceOptions& options,
                                const Eigen::Ref<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>& centres,
                                const std::vector<std::uint64_t>& stream_ids, const ProgressCallback& progress,
                                const PoseSolverFactory& factory) {
  options.validate();
  std::vector<Tile> tiles(static_cast<std::size_t>(centres.rows()));
  for (std::int64_t v = 0; v < centres.rows(); ++v) tiles[v].rows = {v}, tiles[v].neighbours = {{}};
  return evaluate_tiles(model, options, centres, stream_ids, tiles, Strategy::Plain, progress, factory);
}

ReachabilityMap compute_reachability(const ChainModel& model, const WorkspaceOptions& options,
                                     const ProgressCallback& progress, const PoseSolverFactory& factory) {
  options.validate();
  const auto t0 = std::chrono::steady_clock::now();
  ReachabilityMap map;
  map.options = options;
  map.chain_hash = model.hash();
  map.base = model.base_name();
  map.tip = model.tip_name();
  map.reach = model.reach();
  map.tried = options.poses_per_voxel();

  // Lines 1-8 of Algorithm 1: the point cloud, its boundary (or hull), the grid and the voxels inside.
  // Every shard computes the same cloud and boundary (they depend on the seed only), so the list of
  // voxels inside, and with it the split into shards, is the same in all shards.
  const std::vector<Eigen::Vector3d> cloud = sample_tip_positions(model, options.cloud_samples, options.seed);
  map.grid = VoxelGrid::around(Eigen::Vector3d::Zero(), 2.0 * model.reach(), options.voxel_size);
  std::vector<std::int64_t> inside;
  if (options.hull == HullKind::Boundary) {
    const AlphaShape shape = AlphaShape::boundary(cloud, options.shrink);
    map.alpha = shape.alpha();
    map.hull_facets = static_cast<int>(shape.n_boundary_facets());
    inside = shape.voxels_inside(map.grid);
  } else {
    const ConvexHull hull = ConvexHull::of(cloud);
    map.alpha = std::numeric_limits<double>::infinity();
    map.hull_facets = hull.n_facets();
    inside = convex_voxels(hull, map.grid);
  }
  map.hull_voxels = static_cast<std::int64_t>(inside.size());
  // Tiles: the voxels inside, in blocks of kTileLines x kTileLines lines along z. Shard i of N takes
  // the tiles t with t % N == i: a tile is never split, so every voxel sees the same neighbours in
  // every shard and the merged shards equal the unsharded map.
  const int n = map.grid.n;
  const int blocks = (n + kTileLines - 1) / kTileLines;
  std::map<std::int64_t, std::vector<std::int64_t>> by_block;  // block -> grid ids, ascending
  for (const std::int64_t k : inside) {
    const std::int64_t i = k / (static_cast<std::int64_t>(n) * n), j = (k / n) % n;
    by_block[(i / kTileLines) * blocks + j / kTileLines].push_back(k);
  }
  std::vector<std::vector<std::int64_t>> mine;
  std::int64_t tile_index = 0;
  for (auto& [block, ids] : by_block)
    if (tile_index++ % options.shard_count == options.shard_index) mine.push_back(std::move(ids));
  for (const auto& ids : mine) map.voxel_ids.insert(map.voxel_ids.end(), ids.begin(), ids.end());
  std::sort(map.voxel_ids.begin(), map.voxel_ids.end());
  const auto total = static_cast<Eigen::Index>(map.voxel_ids.size());
  map.centres.resize(total, 3);
  for (Eigen::Index v = 0; v < total; ++v) map.centres.row(v) = map.grid.centre_of(map.voxel_ids[v]).transpose();
  // Inside out: each tile is visited from the voxel nearest the cloud's centroid (where the tip is most
  // often, and most directions are reachable) outwards, so that most voxels find solved neighbours.
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& p : cloud) centroid += p / static_cast<double>(cloud.size());
  std::vector<Tile> tiles;
  for (auto& ids : mine) {
    std::stable_sort(ids.begin(), ids.end(), [&](std::int64_t x, std::int64_t y) {
      return (map.grid.centre_of(x) - centroid).squaredNorm() < (map.grid.centre_of(y) - centroid).squaredNorm();
    });
    std::map<std::int64_t, int> position;
    for (std::size_t q = 0; q < ids.size(); ++q) position[ids[q]] = static_cast<int>(q);
    Tile tile;
    for (const std::int64_t k : ids) {
      tile.rows.push_back(std::lower_bound(map.voxel_ids.begin(), map.voxel_ids.end(), k) - map.voxel_ids.begin());
      const int i = static_cast<int>(k / (static_cast<std::int64_t>(n) * n)), j = static_cast<int>((k / n) % n),
                l = static_cast<int>(k % n);
      std::vector<std::pair<int, int>> nb;  // (|offset|_1, position)
      for (int di = -1; di <= 1; ++di)
        for (int dj = -1; dj <= 1; ++dj)
          for (int dl = -1; dl <= 1; ++dl) {
            const int a = i + di, b = j + dj, c = l + dl;
            if ((di | dj | dl) == 0 || a < 0 || b < 0 || c < 0 || a >= n || b >= n || c >= n) continue;
            const auto it = position.find((static_cast<std::int64_t>(a) * n + b) * n + c);
            if (it != position.end()) nb.emplace_back(std::abs(di) + std::abs(dj) + std::abs(dl), it->second);
          }
      std::stable_sort(nb.begin(), nb.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
      tile.neighbours.emplace_back();
      for (const auto& e : nb) tile.neighbours.back().push_back(e.second);
    }
    tiles.push_back(std::move(tile));
  }
  // Largest tiles first, so that no thread is left with a big one at the end (the order of the tiles
  // does not change the map).
  std::stable_sort(tiles.begin(), tiles.end(), [](const Tile& x, const Tile& y) { return x.rows.size() > y.rows.size(); });

  const std::vector<std::uint64_t> streams(map.voxel_ids.begin(), map.voxel_ids.end());
  VoxelEvaluation e = evaluate_tiles(model, options, map.centres, streams, tiles, Strategy::Neighbours, progress, factory);
  map.solved = std::move(e.solved);
  map.reached = std::move(e.reached);
  map.ik_calls = e.ik_calls;
  map.cheap_exits = e.cheap_exits;
  map.threads_used = e.threads_used;
  map.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return map;
}

namespace {
bool same_options(const WorkspaceOptions& a, const WorkspaceOptions& b) {
  return a.voxel_size == b.voxel_size && a.directions == b.directions &&
         (a.free_roll ? b.free_roll : !b.free_roll && a.rolls == b.rolls && a.any_roll == b.any_roll) && a.approach == b.approach &&
         a.timeout == b.timeout && a.epsilon == b.epsilon &&
         a.cloud_samples == b.cloud_samples && a.seed == b.seed && a.shard_count == b.shard_count &&
         a.hull == b.hull && a.map_shrink() == b.map_shrink();
}
}  // namespace

ReachabilityMap merge_shards(const std::vector<ReachabilityMap>& shards) {
  if (shards.empty()) throw InputError("merge needs at least one shard");
  const ReachabilityMap& first = shards.front();
  const int n = first.options.shard_count;
  if (static_cast<int>(shards.size()) != n)
    throw InputError("the map has " + std::to_string(n) + " shards; got " + std::to_string(shards.size()));
  std::vector<bool> seen(n, false);
  for (const auto& s : shards) {
    if (!same_options(s.options, first.options) || s.chain_hash != first.chain_hash ||
        s.hull_voxels != first.hull_voxels || s.grid.n != first.grid.n || s.grid.voxel != first.grid.voxel)
      throw InputError("shards of different maps (parameters, chain or grid differ) cannot be merged");
    const int i = s.options.shard_index;
    if (seen[i]) throw InputError("shard " + std::to_string(i) + "/" + std::to_string(n) + " given twice");
    seen[i] = true;
  }
  // Rows of the merged map by grid index: (shard, row in that shard).
  std::map<std::int64_t, std::pair<std::size_t, std::size_t>> voxels;
  const bool with_bits = std::all_of(shards.begin(), shards.end(), [](const ReachabilityMap& s) {
    return s.reached.size() == s.voxel_ids.size() * reached_bytes_per_voxel(s.tried);
  });
  ReachabilityMap out = first;
  out.ik_calls = out.cheap_exits = 0;
  out.seconds = 0.0;
  for (std::size_t i = 0; i < shards.size(); ++i) {
    const ReachabilityMap& s = shards[i];
    for (std::size_t v = 0; v < s.voxel_ids.size(); ++v)
      if (!voxels.emplace(s.voxel_ids[v], std::make_pair(i, v)).second)
        throw InputError("voxel " + std::to_string(s.voxel_ids[v]) + " appears in two shards");
    out.ik_calls += s.ik_calls;
    out.cheap_exits += s.cheap_exits;
    out.seconds += s.seconds;
  }
  if (static_cast<std::int64_t>(voxels.size()) != first.hull_voxels)
    throw InputError("the shards hold " + std::to_string(voxels.size()) + " voxels; the map has " +
                     std::to_string(first.hull_voxels));
  out.options.shard_index = 0;
  out.options.shard_count = 1;
  out.voxel_ids.clear();
  out.solved.clear();
  out.reached.clear();
  out.base_joints.clear();  // (shards of whole-body maps are not merged here)
  out.base_placements.clear();
  const int bytes = reached_bytes_per_voxel(first.tried);
  out.centres.resize(static_cast<Eigen::Index>(voxels.size()), 3);
  Eigen::Index row = 0;
  for (const auto& [k, where] : voxels) {
    const ReachabilityMap& s = shards[where.first];
    const std::size_t v = where.second;
    out.voxel_ids.push_back(k);
    out.centres.row(row++) = s.centres.row(static_cast<Eigen::Index>(v));
    out.solved.push_back(s.solved[v]);
    if (with_bits) out.reached.insert(out.reached.end(), s.reached.begin() + v * bytes, s.reached.begin() + (v + 1) * bytes);
  }
  return out;
}

void save_npz(const ReachabilityMap& map, const std::string& path, const std::string& command) {
  const auto m = static_cast<std::int64_t>(map.voxel_ids.size());
  const int bytes = reached_bytes_per_voxel(map.tried);
  if (map.tried < 1) throw InputError("a map tries at least one pose per voxel");
  if (map.centres.rows() != m || static_cast<std::int64_t>(map.solved.size()) != m)
    throw InputError("a map needs one centre and one solved count per voxel id");
  if (!map.reached.empty() && static_cast<std::int64_t>(map.reached.size()) != m * bytes)
    throw InputError("a map's per-direction results need " + std::to_string(bytes) + " bytes per voxel");
  if (!std::is_sorted(map.voxel_ids.begin(), map.voxel_ids.end()))
    throw InputError("a map's voxel ids must be ascending");
  if (map.kind != kMapKindHead && map.kind != kMapKindWholeBody)
    throw InputError("a map's kind is 'head' or 'whole-body', got '" + map.kind + "'");
  const std::int64_t poses = m * map.tried;
  if (!map.base_joints.empty() &&
      (map.base_joint_count < 1 || static_cast<std::int64_t>(map.base_joints.size()) != poses * map.base_joint_count))
    throw InputError("a map's base joints need base_joint_count (>= 1) values per voxel and pose");
  if (!map.base_placements.empty() && static_cast<std::int64_t>(map.base_placements.size()) != poses * 3)
    throw InputError("a map's base placements need 3 values (x, y, yaw) per voxel and pose");
  NpzWriter w;
  w.add_string("format", kMapFormat);
  std::vector<double> centres(map.centres.data(), map.centres.data() + map.centres.size());
  w.add_f64("centers", centres, {m, 3});
  const Eigen::VectorXd d = map.indices();
  w.add_f64("indices", std::vector<double>(d.data(), d.data() + d.size()), {m});
  w.add_i32("solved", map.solved, {m});
  w.add_i64("voxel_ids", map.voxel_ids, {m});
  if (!map.reached.empty()) w.add_u8("reached", map.reached, {m, bytes});
  w.add_string("map_kind", map.kind);
  if (!map.base_joints.empty()) w.add_f64("base_joints", map.base_joints, {m, map.tried, map.base_joint_count});
  if (!map.base_placements.empty()) w.add_f64("base_placements", map.base_placements, {m, map.tried, 3});
  w.add_scalar("tried", static_cast<std::int64_t>(map.tried));
  const WorkspaceOptions& o = map.options;
  // The directions of every voxel's sphere, so that a reader needs numpy alone.
  std::vector<double> dirs;
  for (const auto& v : fibonacci_directions(o.directions)) dirs.insert(dirs.end(), {v.x(), v.y(), v.z()});
  w.add_f64("sphere_directions", dirs, {o.directions, 3});
  w.add_f64("grid_origin", {map.grid.origin.x(), map.grid.origin.y(), map.grid.origin.z()}, {3});
  w.add_scalar("grid_size", map.grid.side());
  w.add_i64("grid_shape", {map.grid.n, map.grid.n, map.grid.n}, {3});
  w.add_scalar("hull_voxels", map.hull_voxels);
  w.add_scalar("hull_facets", static_cast<std::int64_t>(map.hull_facets));
  w.add_string("hull", hull_kind_name(o.hull));
  w.add_scalar("shrink", o.map_shrink());
  w.add_scalar("alpha", map.alpha);
  w.add_scalar("reach", map.reach);
  w.add_scalar("voxel_size", o.voxel_size);
  w.add_scalar("directions", static_cast<std::int64_t>(o.directions));
  w.add_scalar("rolls", static_cast<std::int64_t>(o.free_roll ? 0 : o.rolls));
  w.add_bool("free_roll", o.free_roll);
  w.add_bool("any_roll", o.any_roll);
  w.add_string("approach_axis", approach_axis_name(o.approach));
  w.add_scalar("timeout", o.timeout);
  w.add_scalar("epsilon", o.epsilon);
  w.add_scalar("cloud_samples", static_cast<std::int64_t>(o.cloud_samples));
  w.add_u64("seed", {o.seed}, {});
  w.add_i64("shard", {o.shard_index, o.shard_count}, {2});
  w.add_string("chain_hash", map.chain_hash);
  w.add_string("base", map.base);
  w.add_string("tip", map.tip);
  w.add_string("command", command);
  w.add_scalar("ik_calls", map.ik_calls);
  w.add_scalar("cheap_exits", map.cheap_exits);
  w.add_scalar("seconds", map.seconds);
  w.add_scalar("threads", static_cast<std::int64_t>(map.threads_used));
  try {
    w.write(path);
  } catch (const std::runtime_error& e) {
    throw InputError(e.what());
  }
}

}  // namespace snakehead
