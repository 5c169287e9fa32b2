// The workspace sweep (Algorithm 1, lines 9-21, over the voxels inside the boundary): tiles of neighbouring voxels,
// each evaluated start to finish by one worker (TileEvaluator), dealt to the core's threads by parallel_for_each.
#include "snakehead/workspace.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <random>

#include "snakehead/alpha_shape.hpp"
#include "snakehead/core_threads.hpp"
#include "snakehead/kinematics.hpp"
#include "snakehead/parallel_for.hpp"
#include "snakehead/random_numbers.hpp"

namespace snakehead {
namespace {

constexpr std::uint64_t kVoxelSalt = 0x70CE1;
constexpr std::uint64_t kNeighbourSalt = 0x4E1B;

// Shares of the IK budget (the options' timeout) in the sweep. A call that starts from a neighbouring voxel's
// solution of the same frame, or from the free-roll solution of the same point, converges in a few Newton steps when
// the frame is reachable: a small share of a full budget's evaluations (bench/RESULTS.md).
constexpr double kNearBudget = 1.0 / 3.0;  // from a neighbour's solution (a failure falls back to the full search)
constexpr double kRollBudget = 0.5;        // a rolled frame from the free-roll solution
constexpr double kBriefBudget = 0.25;      // a direction the visited neighbours say is unreachable

// The sweep's tiles are blocks of kTileLines x kTileLines grid lines along z (part of what defines a map).
constexpr int kTileLines = 4;

using Centres = Eigen::Ref<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>;

// A tile: voxels computed together by one thread, each starting from its neighbours' results.
// `rows` index the centres in the order they are visited; `neighbours[k]` lists, for the k-th visited
// voxel, the positions in `rows` of its neighbours in the tile (face neighbours first).
struct Tile {
  std::vector<std::int64_t> rows;
  std::vector<std::vector<int>> neighbours;
};

// The sweep's strategy. Plain: every frame from random guesses with the full budget, as Algorithm 1 states it (the
// independent reference of evaluate_voxels). Neighbours: the strategy below (TileEvaluator).
enum class Strategy { Plain, Neighbours };

// What every tile of a sweep shares: the voxels, the options and what follows from them.
//
// A voxel's "units" are what the index counts: its directions when any roll will do (the paper's rule, and free
// roll), else its (direction, roll) frames. A unit is reached when one of its candidate frames is solved.
struct SweepSetup {
  SweepSetup(const ChainModel& model, const WorkspaceOptions& options, const Centres& centres,
             const std::vector<std::uint64_t>& stream_ids, Strategy strategy)
      : model(model), options(options), centres(centres), stream_ids(stream_ids),
        dirs(fibonacci_directions(options.directions)), bound(model, options), range(model),
        radius(0.5 * options.voxel_size), n_dirs(options.directions), n_rolls(options.free_roll ? 1 : options.rolls),
        per_unit(options.free_roll || !options.any_roll ? 1 : options.rolls), units(options.poses_per_voxel()),
        frames_per_voxel(n_dirs * n_rolls), bytes_per_voxel(reached_bytes_per_voxel(units)),
        // the free-roll test pays when it can replace more than one fixed-roll call per direction
        probe_directions(strategy == Strategy::Neighbours && !options.free_roll && n_rolls > 1),
        neighbours_help(strategy == Strategy::Neighbours) {}

  // The direction of unit u.
  int direction_of(int u) const { return options.any_roll || options.free_roll ? u : u / n_rolls; }

  const ChainModel& model;
  const WorkspaceOptions& options;
  const Centres& centres;
  const std::vector<std::uint64_t>& stream_ids;
  const std::vector<Eigen::Vector3d> dirs;
  const ReachBound bound;
  const SamplingRange range;
  const double radius;  // m: of each voxel's sphere
  const int n_dirs, n_rolls;
  const int per_unit;  // candidate frames per unit
  const int units, frames_per_voxel, bytes_per_voxel;
  const bool probe_directions, neighbours_help;
};

// One worker of the sweep: evaluates tiles one after the other with its own solver and buffers, each in a fixed
// order, so that a tile's result depends on the tile alone.
//
// Frame c of a voxel is frame c of its neighbour moved by one voxel, so a neighbour's solution is an excellent
// initial guess (a few Newton steps away when reachable). Unreachable frames dominate the cost: each spends the
// whole IK budget. Three things make them cheap:
// - a direction's rolled frames are not tried one by one from random guesses: one IK call with the roll left free
//   (a relaxation: it solves whenever one of the rolled frames can be solved) decides first (probe). When it fails,
//   the direction is unreached without a call per roll; when it succeeds, the rolled frames are tried from its
//   solution, nearest roll first;
// - a voxel whose visited neighbours include one that failed a direction with the full budget, and none that
//   reached it, tests that direction with a short budget (unreachable regions are wide);
// - calls that start from a neighbour's solution get a short budget (reachable ones converge fast).
// What a short budget misses is recovered by propagation: a unit still unreached whose neighbour reached it is tried
// again from that neighbour's solution (second chances).
class TileEvaluator {
 public:
  TileEvaluator(const SweepSetup& s, PoseSolver& solver) : s_(s), solver_(solver), q_out_(s.model.n_joints()),
                                                           order_(static_cast<std::size_t>(s.n_rolls)) {}

  // The tile's voxels' solved counts and reached bits into out (their rows only).
  void evaluate(const Tile& tile, VoxelEvaluation& out) {
    start(tile);
    for (std::int64_t a = 0; a < n_vox_; ++a) voxel_frames(a);
    for (int a = 0; a < static_cast<int>(n_vox_); ++a) {
      for (int u = 0; u < s_.units; ++u) visit(a, u);
      visited_[a] = 1;
    }
    if (s_.neighbours_help) second_chances();
    write(out);
  }

  std::int64_t ik_calls = 0, cheap_exits = 0;

 private:
  // The buffers sized for the tile and cleared.
  void start(const Tile& tile) {
    tile_ = &tile;
    n_vox_ = static_cast<std::int64_t>(tile.rows.size());
    const std::int64_t n_frames = n_vox_ * s_.frames_per_voxel, n_directions = n_vox_ * s_.n_dirs;
    targets_.resize(n_frames);
    possible_.assign(n_frames, 0);
    guesses_.resize(n_frames);
    seeds_.resize(n_frames);
    probe_possible_.assign(n_directions, 0);
    probe_state_.assign(n_directions, 0);
    probe_roll_.assign(n_directions, 0.0);
    probe_q_.resize(n_directions);
    probe_seeds_.resize(n_directions);
    reached_by_.assign(n_vox_ * s_.units, -1);
    dir_state_.assign(n_directions, 0);
    no_roll_.assign(n_directions, 0);
    tried_from_.assign(n_vox_ * s_.units, 0);
    solutions_.resize(n_vox_ * s_.units);
    visited_.assign(n_vox_, 0);
  }

  // Lines 11-15 for voxel a of the tile: its frames (frame index = (voxel, direction, roll)), the cheap exits, and
  // each frame's random guess and IK seed from the voxel's own stream.
  void voxel_frames(std::int64_t a) {
    const std::int64_t row = tile_->rows[a];
    const Eigen::Vector3d c = s_.centres.row(row).transpose();
    std::mt19937_64 rng(stream_seed(s_.options.seed, kVoxelSalt, s_.stream_ids[row]));
    // The whole sphere beyond the tip's reach: index 0 without looking at a single frame.
    const bool in_reach = c.norm() - s_.radius <= s_.bound.reach() + 1e-9;
    for (int di = 0; di < s_.n_dirs; ++di) {
      const Eigen::Vector3d& d = s_.dirs[di];
      const Eigen::Vector3d p = c + s_.radius * d;
      const std::int64_t dir = a * s_.n_dirs + di;
      probe_possible_[dir] = in_reach && s_.bound.possible_any_roll(p, d);
      for (int r = 0; r < s_.n_rolls; ++r) {
        const std::int64_t f = dir * s_.n_rolls + r;
        targets_[f] = approach_frame(p, d, 2.0 * M_PI * r / s_.n_rolls, s_.options.approach);
        possible_[f] = in_reach && (s_.options.free_roll ? probe_possible_[dir] : s_.bound.possible(targets_[f]));
        cheap_exits += !possible_[f];
        s_.range.draw(rng, guesses_[f]);
        seeds_[f] = rng();
      }
    }
    for (int di = 0; di < s_.n_dirs; ++di) probe_seeds_[a * s_.n_dirs + di] = rng();
  }

  // The first visit of unit u of voxel a: from a visited neighbour's solution, else from random guesses, or from the
  // free-roll test of its direction.
  void visit(int a, int u) {
    const std::int64_t unit = static_cast<std::int64_t>(a) * s_.units + u;
    if (s_.neighbours_help && from_neighbours(a, u, 1, false)) {
      dir_state_[static_cast<std::size_t>(a) * s_.n_dirs + s_.direction_of(u)] = 1;
      return;
    }
    if (!s_.probe_directions) {
      from_guesses(a, u, unit);
      return;
    }
    // Directions: unit u is direction u (any roll) or frame u of direction u / n_rolls (each roll).
    const int di = s_.options.any_roll ? u : u / s_.n_rolls;
    const std::int64_t dir = static_cast<std::int64_t>(a) * s_.n_dirs + di;
    if (!probe(a, di)) return;
    if (s_.options.any_roll)
      from_probe_rolls(a, u, unit, di, dir);
    else
      attempt(unit, 0, probe_q_[dir], seeds_[unit], kRollBudget);
  }

  // Each candidate frame of the unit from its random guess (short budget where the neighbours say unreachable).
  void from_guesses(int a, int u, std::int64_t unit) {
    const int di = s_.direction_of(u);
    const bool brief = looks_unreachable(a, di);
    for (int c = 0; c < s_.per_unit; ++c) {
      const std::int64_t f = unit * s_.per_unit + c;
      if (attempt(unit, c, guesses_[f], seeds_[f], brief ? kBriefBudget : 1.0)) break;
    }
    signed char& state = dir_state_[static_cast<std::size_t>(a) * s_.n_dirs + di];
    if (reached_by_[unit] >= 0) state = 1;
    else if (state == 0) state = brief ? -2 : -1;
  }

  // The rolled frames of direction di (any roll) from its free-roll solution, nearest roll first; only the nearest
  // where a visited neighbour solved the direction with its roll free but at none of the rolls (rollless).
  void from_probe_rolls(int a, int u, std::int64_t unit, int di, std::int64_t dir) {
    roll_order(dir);
    const bool one = rollless(a, u, di);
    int tried = 0;
    for (int k = 0; k < s_.n_rolls && tried < (one ? 1 : s_.n_rolls); ++k) {
      const int c = order_[k];
      if (!possible_[unit * s_.per_unit + c]) continue;
      ++tried;
      if (attempt(unit, c, probe_q_[dir], seeds_[unit * s_.per_unit + c], kRollBudget)) break;
    }
    if (tried > 0 && reached_by_[unit] < 0) no_roll_[dir] = 1;
  }

  // Whether a visited neighbour of voxel a solved direction di with its roll free but at none of the rolls, and no
  // visited neighbour reached unit u.
  bool rollless(int a, int u, int di) const {
    bool rollless = false;
    for (int b : tile_->neighbours[a]) {
      if (!visited_[b]) continue;
      if (reached_by_[static_cast<std::int64_t>(b) * s_.units + u] >= 0) return false;
      rollless |= no_roll_[static_cast<std::size_t>(b) * s_.n_dirs + di] != 0;
    }
    return rollless;
  }

  // One IK call for candidate c of the unit (none when a reach bound excludes it); true when solved.
  bool attempt(std::int64_t unit, int c, const Eigen::VectorXd& q_init, std::uint64_t seed, double budget) {
    const std::int64_t f = unit * s_.per_unit + c;
    if (!possible_[f]) return false;
    ++ik_calls;
    if (!solver_.solve(targets_[f], q_init, seed, budget, q_out_)) return false;
    reached_by_[unit] = c;
    solutions_[unit] = q_out_;
    return true;
  }

  // Whether the visited neighbours of voxel a say that direction di is unreachable: one failed it with the full
  // budget and none reached it.
  bool looks_unreachable(int a, int di) const {
    if (!s_.neighbours_help) return false;
    bool full_failure = false;
    for (int b : tile_->neighbours[a]) {
      if (!visited_[b]) continue;
      const signed char s = dir_state_[static_cast<std::size_t>(b) * s_.n_dirs + di];
      if (s > 0) return false;
      full_failure |= s == -1;
    }
    return full_failure;
  }

  // The free-roll test of direction di of voxel a (once): true when some roll of it is reachable.
  bool probe(int a, int di) {
    const std::int64_t dir = static_cast<std::int64_t>(a) * s_.n_dirs + di;
    if (probe_state_[dir] != 0) return probe_state_[dir] > 0;
    probe_state_[dir] = -1;
    const std::int64_t f0 = dir * s_.n_rolls;  // the roll-0 frame of the direction
    if (!probe_possible_[dir]) return false;
    const bool brief = looks_unreachable(a, di);
    ++ik_calls;
    if (!solver_.solve_free_roll(targets_[f0], probe_start(a, di, f0), probe_seeds_[dir], brief ? kBriefBudget : 1.0,
                                 q_out_)) {
      probe_state_[dir] = dir_state_[dir] = brief ? -2 : -1;
      return false;
    }
    probe_state_[dir] = dir_state_[dir] = 1;
    probe_q_[dir] = q_out_;
    // Roll of the solution about the approach axis, relative to the roll-0 frame.
    const Eigen::Matrix3d rel = targets_[f0].linear().transpose() * forward_kinematics(s_.model, q_out_).linear();
    probe_roll_[dir] = s_.options.approach == ApproachAxis::X ? std::atan2(rel(2, 1), rel(1, 1))
                                                                : std::atan2(rel(1, 0), rel(0, 0));
    return true;
  }

  // Where the free-roll test of direction di of voxel a starts: a visited neighbour's free-roll solution of the same
  // direction, else the random guess of its roll-0 frame f0.
  const Eigen::VectorXd& probe_start(int a, int di, std::int64_t f0) const {
    for (int b : tile_->neighbours[a])
      if (visited_[b] && probe_state_[static_cast<std::size_t>(b) * s_.n_dirs + di] > 0)
        return probe_q_[static_cast<std::size_t>(b) * s_.n_dirs + di];
    return guesses_[f0];
  }

  // The rolled frames of a direction in the order to try them (order_): nearest the free-roll solution's first.
  void roll_order(std::int64_t dir) {
    std::iota(order_.begin(), order_.end(), 0);
    const double psi = probe_roll_[dir];
    auto gap = [&](int r) { return std::abs(std::remainder(2.0 * M_PI * r / s_.n_rolls - psi, 2.0 * M_PI)); };
    std::stable_sort(order_.begin(), order_.end(), [&](int x, int y) { return gap(x) < gap(y); });
  }

  // Tries unit u of voxel a from the solutions of its neighbours that reached it (each neighbour at most once over
  // the tile, at most `most` of them now; later_only: only neighbours visited after a).
  bool from_neighbours(int a, int u, int most, bool later_only) {
    const std::int64_t unit = static_cast<std::int64_t>(a) * s_.units + u;
    const auto& nb = tile_->neighbours[a];
    for (std::size_t k = 0; k < nb.size() && k < 32 && most > 0; ++k) {
      const std::int64_t other = static_cast<std::int64_t>(nb[k]) * s_.units + u;
      if ((later_only && nb[k] < a) || reached_by_[other] < 0 || (tried_from_[unit] >> k) & 1U) continue;
      tried_from_[unit] |= 1U << k;
      --most;
      const int c = reached_by_[other];
      if (attempt(unit, c, solutions_[other], splitmix64(seeds_[unit * s_.per_unit + c] ^ (kNeighbourSalt + k)),
                  kNearBudget))
        return true;
    }
    return false;
  }

  // Second chances, in reverse order: units still unreached are tried from a neighbour visited after them that
  // reached them.
  void second_chances() {
    for (int a = static_cast<int>(n_vox_) - 1; a >= 0; --a)
      for (int u = 0; u < s_.units; ++u)
        if (reached_by_[static_cast<std::int64_t>(a) * s_.units + u] < 0) from_neighbours(a, u, 1, true);
  }

  // Each voxel's count of reached units and their bits into out.
  void write(VoxelEvaluation& out) const {
    for (std::int64_t a = 0; a < n_vox_; ++a) {
      int count = 0;
      std::uint8_t* bits = &out.reached[static_cast<std::size_t>(tile_->rows[a]) * s_.bytes_per_voxel];
      for (int u = 0; u < s_.units; ++u) {
        if (reached_by_[a * s_.units + u] < 0) continue;
        ++count;
        bits[u / 8] |= static_cast<std::uint8_t>(1U << (u % 8));
      }
      out.solved[tile_->rows[a]] = count;
    }
  }

  const SweepSetup& s_;
  PoseSolver& solver_;
  Eigen::VectorXd q_out_;
  const Tile* tile_ = nullptr;
  std::int64_t n_vox_ = 0;
  std::vector<char> visited_;  // per voxel of the tile: its first visit is done
  std::vector<Eigen::Isometry3d, Eigen::aligned_allocator<Eigen::Isometry3d>> targets_;
  std::vector<char> possible_, probe_possible_;
  // Per (voxel, direction) of the free-roll test, and per unit of what decides it without neighbours:
  // 0 not tried, 1 solved, -1 failed with the full budget, -2 failed with a short one.
  std::vector<signed char> probe_state_, dir_state_, no_roll_;
  std::vector<double> probe_roll_;  // the roll of the free-roll solution (rad)
  std::vector<int> reached_by_;     // per unit: the candidate that reached it, or -1
  std::vector<std::uint32_t> tried_from_;  // per unit: neighbours (bit = position in the list) tried from
  std::vector<Eigen::VectorXd> solutions_, guesses_, probe_q_;
  std::vector<std::uint64_t> seeds_, probe_seeds_;
  std::vector<int> order_;
};

// The sweep's progress as a LoopWatch: progress(done, total) on the calling thread.
LoopWatch progress_watch(const ProgressCallback& progress, const std::atomic<std::int64_t>& done, std::int64_t total) {
  return {[&progress, &done, total] { return progress(done.load(), total); }, std::chrono::milliseconds(100)};
}

// Lines 9-21 of Algorithm 1 over the tiles: one tile at a time to each of the threads, a TileEvaluator (and a pose
// solver) per thread. The result does not depend on the thread count.
VoxelEvaluation evaluate_tiles(const ChainModel& model, const WorkspaceOptions& options, const Centres& centres,
                               const std::vector<std::uint64_t>& stream_ids, const std::vector<Tile>& tiles,
                               Strategy strategy, const ProgressCallback& progress, const PoseSolverFactory& factory_in) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto total = static_cast<std::int64_t>(centres.rows());
  if (static_cast<std::int64_t>(stream_ids.size()) != total)
    throw InputError("one stream id per voxel centre is needed");
  if (!centres.allFinite()) throw InputError("voxel centres must be finite");
  const PoseSolverFactory factory = factory_in ? factory_in : trac_ik_solver_factory();
  const SweepSetup setup(model, options, centres, stream_ids, strategy);
  VoxelEvaluation out;
  out.tried = options.poses_per_voxel();
  out.solved.assign(total, 0);
  out.reached.assign(static_cast<std::size_t>(total) * setup.bytes_per_voxel, 0);
  const int threads = options.threads > 0 ? options.threads : core_threads();
  out.threads_used = static_cast<int>(
      std::max<std::int64_t>(1, std::min<std::int64_t>(std::max(threads, 1), static_cast<std::int64_t>(tiles.size()))));
  // Solvers are made here, so that a bad option fails before any thread starts.
  std::vector<std::unique_ptr<PoseSolver>> solvers;
  std::vector<TileEvaluator> workers;
  workers.reserve(static_cast<std::size_t>(out.threads_used));
  for (int t = 0; t < out.threads_used; ++t) {
    solvers.push_back(factory(model, options));
    workers.emplace_back(setup, *solvers.back());
  }
  std::atomic<std::int64_t> done{0};
  const LoopWatch watch = progress_watch(progress, done, total);
  const bool finished = parallel_for_each(static_cast<long>(tiles.size()), out.threads_used, [&](int w, long t) {
    workers[static_cast<std::size_t>(w)].evaluate(tiles[static_cast<std::size_t>(t)], out);
    done += static_cast<std::int64_t>(tiles[static_cast<std::size_t>(t)].rows.size());
  }, progress ? &watch : nullptr);
  if (!finished) throw Cancelled("workspace sweep cancelled");
  if (progress) progress(done.load(), total);
  for (const TileEvaluator& w : workers) {
    out.ik_calls += w.ik_calls;
    out.cheap_exits += w.cheap_exits;
  }
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

// Lines 1-8 of Algorithm 1 past the cloud: the grid and the voxels inside the cloud's boundary (or hull), ascending;
// the map's grid, alpha, hull facets and in-hull voxels are set.
std::vector<std::int64_t> voxels_inside(const std::vector<Eigen::Vector3d>& cloud, const ChainModel& model,
                                        const WorkspaceOptions& options, ReachabilityMap& map) {
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
  return inside;
}

// This shard's tiles' voxels (grid ids, ascending in each): the voxels inside, in blocks of kTileLines x kTileLines
// lines along z; shard i of N takes the tiles t with t % N == i. A tile is never split, so every voxel sees the same
// neighbours in every shard and the merged shards equal the unsharded map.
std::vector<std::vector<std::int64_t>> shard_tiles(const std::vector<std::int64_t>& inside, int n,
                                                   const WorkspaceOptions& options) {
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
  return mine;
}

// The tile of voxels `ids` (grid ids), visited inside out: from the voxel nearest the cloud's centroid (where the
// tip is most often, and most directions are reachable) outwards, so that most voxels find solved neighbours; each
// voxel's neighbours in the tile, face neighbours first. Rows: positions in the map's voxel_ids.
Tile make_tile(std::vector<std::int64_t> ids, const ReachabilityMap& map, const Eigen::Vector3d& centroid) {
  const int n = map.grid.n;
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
  return tile;
}

// The shard's tiles (`mine`, as shard_tiles gives them) as the map's voxels (voxel_ids, centres) and Tiles, largest
// first, so that no thread is left with a big one at the end (the order of the tiles does not change the map).
std::vector<Tile> map_tiles(std::vector<std::vector<std::int64_t>> mine, const std::vector<Eigen::Vector3d>& cloud,
                            ReachabilityMap& map) {
  for (const auto& ids : mine) map.voxel_ids.insert(map.voxel_ids.end(), ids.begin(), ids.end());
  std::sort(map.voxel_ids.begin(), map.voxel_ids.end());
  const auto total = static_cast<Eigen::Index>(map.voxel_ids.size());
  map.centres.resize(total, 3);
  for (Eigen::Index v = 0; v < total; ++v) map.centres.row(v) = map.grid.centre_of(map.voxel_ids[v]).transpose();
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& p : cloud) centroid += p / static_cast<double>(cloud.size());
  std::vector<Tile> tiles;
  for (auto& ids : mine) tiles.push_back(make_tile(std::move(ids), map, centroid));
  std::stable_sort(tiles.begin(), tiles.end(), [](const Tile& x, const Tile& y) { return x.rows.size() > y.rows.size(); });
  return tiles;
}

}  // namespace

VoxelEvaluation evaluate_voxels(const ChainModel& model, const WorkspaceOptions& options, const Centres& centres,
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
  // Lines 1-8 of Algorithm 1: the point cloud, its boundary (or hull), the grid and the voxels inside. Every shard
  // computes the same cloud and boundary (they depend on the seed only), so the list of voxels inside, and with it
  // the split into shards, is the same in all shards.
  const std::vector<Eigen::Vector3d> cloud = sample_tip_positions(model, options.cloud_samples, options.seed);
  const std::vector<std::int64_t> inside = voxels_inside(cloud, model, options, map);
  const std::vector<Tile> tiles = map_tiles(shard_tiles(inside, map.grid.n, options), cloud, map);
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

}  // namespace snakehead
