// The workspace sweep (Algorithm 1): geometry helpers, the hull, cheap exits, determinism across
// thread counts, shards, the .npz writer and bad input.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdio>
#include <fstream>
#include <map>
#include <mutex>
#include <random>
#include <set>
#include <sstream>

#include "snakehead/alpha_shape.hpp"
#include "snakehead/kinematics.hpp"
#include "snakehead/npz.hpp"
#include "snakehead/workspace.hpp"

using namespace snakehead;

namespace {

const std::string kSnake = std::string(SNAKEHEAD_URDF_DIR) + "/snake16.urdf";

const ChainModel& head7() {
  static const ChainModel m = ChainModel::from_urdf(kSnake, "neck_end", "head_tip");
  return m;
}

// A coarse, quick map: ~30 voxels in the hull, 6 poses each.
WorkspaceOptions coarse() {
  WorkspaceOptions o;
  o.voxel_size = 0.2;
  o.directions = 3;
  o.rolls = 2;
  o.timeout = 0.002;
  o.cloud_samples = 2000;
  o.seed = 7;
  return o;
}

// A stand-in solver with a known answer: a pose is "reachable" when its position's z >= 0. Counts calls.
struct HalfSpaceSolver : PoseSolver {
  explicit HalfSpaceSolver(std::atomic<long>* calls) : calls(calls) {}
  bool solve(const Eigen::Isometry3d& target, const Eigen::VectorXd&, std::uint64_t, double, Eigen::VectorXd&) override {
    ++*calls;
    return target.translation().z() >= 0.0;
  }
  std::atomic<long>* calls;
};

PoseSolverFactory half_space(std::atomic<long>* calls) {
  return [calls](const ChainModel&, const WorkspaceOptions&) { return std::make_unique<HalfSpaceSolver>(calls); };
}

Eigen::VectorXd random_q(const ChainModel& m, std::mt19937& rng) {
  Eigen::VectorXd q(m.n_joints());
  for (int i = 0; i < m.n_joints(); ++i) q[i] = std::uniform_real_distribution<double>(m.lower()[i], m.upper()[i])(rng);
  return q;
}

}  // namespace

TEST(Fibonacci, UnitAndEvenlySpread) {
  for (int n : {1, 2, 7, 20, 200}) {
    const auto d = fibonacci_directions(n);
    ASSERT_EQ(static_cast<int>(d.size()), n);
    for (const auto& v : d) EXPECT_NEAR(v.norm(), 1.0, 1e-12);
  }
  // Evenly spread: the mean is near 0, the second moment near I/3, every octant holds about n/8
  // points, and no two points are much closer than the spacing of an even covering (sqrt(4 pi / n)).
  const int n = 400;
  const auto d = fibonacci_directions(n);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
  int octant[8] = {0};
  double closest = 10.0;
  for (int i = 0; i < n; ++i) {
    mean += d[i] / n;
    second += d[i] * d[i].transpose() / n;
    ++octant[(d[i].x() > 0) + 2 * (d[i].y() > 0) + 4 * (d[i].z() > 0)];
    for (int j = 0; j < i; ++j) closest = std::min(closest, (d[i] - d[j]).norm());
  }
  EXPECT_LT(mean.norm(), 0.01);
  EXPECT_LT((second - Eigen::Matrix3d::Identity() / 3).cwiseAbs().maxCoeff(), 0.01);
  for (int k = 0; k < 8; ++k) EXPECT_NEAR(octant[k], n / 8, 4) << "octant " << k;
  EXPECT_GT(closest, 0.7 * std::sqrt(4 * M_PI / n));
  EXPECT_THROW(fibonacci_directions(0), InputError);
}

TEST(ApproachFrame, ApproachAxisIsTheDirectionAndRollsTurnAboutIt) {
  std::mt19937 rng(3);
  std::normal_distribution<double> g;
  for (int k = 0; k < 200; ++k) {
    const Eigen::Vector3d dir(g(rng), g(rng), g(rng));
    const Eigen::Vector3d p(g(rng), g(rng), g(rng));
    const double roll = std::uniform_real_distribution<double>(-4, 4)(rng);
    for (ApproachAxis ax : {ApproachAxis::X, ApproachAxis::Z}) {
      const int col = ax == ApproachAxis::X ? 0 : 2;
      const Eigen::Isometry3d f = approach_frame(p, dir, roll, ax);
      const Eigen::Matrix3d R = f.linear();
      EXPECT_LT((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), 1e-12);
      EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
      EXPECT_LT((R.col(col) - dir.normalized()).norm(), 1e-12);
      EXPECT_LT((f.translation() - p).norm(), 1e-15);
      // Roll: the frame at roll r is the roll-0 frame turned by r about its own approach axis.
      const Eigen::Isometry3d f0 = approach_frame(p, dir, 0.0, ax);
      const Eigen::Vector3d local = Eigen::Vector3d::Unit(col);
      EXPECT_LT((f0.linear() * Eigen::AngleAxisd(roll, local).toRotationMatrix() - R).norm(), 1e-12);
    }
  }
  EXPECT_THROW(approach_frame(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), 0, ApproachAxis::X), InputError);
  EXPECT_EQ(parse_approach_axis("z"), ApproachAxis::Z);
  EXPECT_THROW(parse_approach_axis("y"), InputError);
}

TEST(Grid, CentredCubeOfVoxels) {
  const VoxelGrid g = VoxelGrid::around(Eigen::Vector3d::Zero(), 1.13, 0.05);
  EXPECT_EQ(g.n, 23);  // ceil(1.13 / 0.05)
  EXPECT_NEAR(g.side(), 1.15, 1e-12);
  EXPECT_LT((g.origin + Eigen::Vector3d::Constant(0.575)).norm(), 1e-12);
  EXPECT_LT((g.centre_of(0) - (g.origin + Eigen::Vector3d::Constant(0.025))).norm(), 1e-12);
  // Index (i, j, l) = (1, 2, 3): x from i, z from l.
  EXPECT_LT((g.centre_of((1 * 23 + 2) * 23 + 3) - (g.origin + 0.05 * Eigen::Vector3d(1.5, 2.5, 3.5))).norm(), 1e-12);
  // The central voxel sits on the base origin (odd n).
  EXPECT_LT(g.centre_of((11 * 23 + 11) * 23 + 11).norm(), 1e-12);
  EXPECT_THROW(VoxelGrid::around(Eigen::Vector3d::Zero(), 1.0, 0.0), InputError);
}

TEST(Hull, CubeAgainstItsPlanes) {
  std::vector<Eigen::Vector3d> pts;
  for (int c = 0; c < 8; ++c) pts.emplace_back(c & 1, (c >> 1) & 1, (c >> 2) & 1);
  std::mt19937 rng(1);
  for (int k = 0; k < 100; ++k)
    pts.emplace_back(std::uniform_real_distribution<double>(0.1, 0.9)(rng), 0.5, std::uniform_real_distribution<double>(0.1, 0.9)(rng));
  const ConvexHull h = ConvexHull::of(pts);
  EXPECT_EQ(h.n_vertices, 8);
  EXPECT_NEAR(h.volume, 1.0, 1e-9);
  for (int k = 0; k < h.n_facets(); ++k) EXPECT_NEAR(h.normals.row(k).norm(), 1.0, 1e-9);
  EXPECT_TRUE(h.contains(Eigen::Vector3d(0.5, 0.5, 0.5)));
  EXPECT_TRUE(h.contains(Eigen::Vector3d(0.01, 0.99, 0.5)));
  EXPECT_FALSE(h.contains(Eigen::Vector3d(1.01, 0.5, 0.5)));
  EXPECT_FALSE(h.contains(Eigen::Vector3d(0.5, -0.01, 0.5)));
  // Points on a plane span no volume.
  std::vector<Eigen::Vector3d> flat;
  for (int k = 0; k < 10; ++k) flat.emplace_back(k, k * k, 0.0);
  EXPECT_THROW(ConvexHull::of(flat), InputError);
}

TEST(ReachBounds, NeverRejectAReachablePose) {
  for (const char* base : {"neck_end", "link_10"}) {
    const ChainModel m = ChainModel::from_urdf(kSnake, base, "head_tip");
    for (ApproachAxis ax : {ApproachAxis::X, ApproachAxis::Z}) {
      WorkspaceOptions o;
      o.approach = ax;
      const ReachBound b(m, o);
      std::mt19937 rng(11);
      for (int k = 0; k < 3000; ++k) {
        const Eigen::Isometry3d t = forward_kinematics(m, random_q(m, rng));
        ASSERT_TRUE(b.possible(t));
        const Eigen::Vector3d a = t.linear().col(ax == ApproachAxis::X ? 0 : 2);
        ASSERT_TRUE(b.possible_any_roll(t.translation(), a));
      }
    }
  }
}

TEST(ReachBounds, RejectPosesBeyondReach) {
  const ChainModel& m = head7();
  WorkspaceOptions o;
  const ReachBound b(m, o);
  // Fully stretched along x, the tip is at reach(); pointing back at the base from there, the
  // last joint would have to be beyond the reach of the others.
  const Eigen::Vector3d tip(m.reach() - 1e-3, 0, 0);
  EXPECT_TRUE(b.possible(approach_frame(tip, Eigen::Vector3d::UnitX(), 0.0, ApproachAxis::X)));
  EXPECT_FALSE(b.possible(approach_frame(tip, -Eigen::Vector3d::UnitX(), 0.0, ApproachAxis::X)));
  EXPECT_FALSE(b.possible_any_roll(tip, -Eigen::Vector3d::UnitX()));
  EXPECT_FALSE(b.possible(approach_frame(Eigen::Vector3d(0, 0, 2 * m.reach()), Eigen::Vector3d::UnitZ(), 0.0,
                                         ApproachAxis::X)));
}

TEST(Sweep, VoxelBeyondReachHasIndexZeroWithoutIK) {
  const ChainModel& m = head7();
  WorkspaceOptions o = coarse();
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> c(2, 3);
  c << 0, 0, 2 * m.reach(), m.reach() + 0.11, 0, 0;  // both spheres (radius 0.1) wholly out of reach
  std::atomic<long> calls{0};
  // Even a solver that would accept these poses (z >= 0) is never asked.
  const VoxelEvaluation e = evaluate_voxels(m, o, c, {0, 1}, nullptr, half_space(&calls));
  EXPECT_EQ(e.solved, (std::vector<std::int32_t>{0, 0}));
  EXPECT_EQ(calls.load(), 0);
  EXPECT_EQ(e.cheap_exits, 2 * o.directions * o.rolls);  // every frame of both voxels
  // And with TRAC-IK.
  const VoxelEvaluation t = evaluate_voxels(m, o, c, {0, 1});
  EXPECT_EQ(t.solved, (std::vector<std::int32_t>{0, 0}));
  EXPECT_EQ(t.ik_calls, 0);
}

// A stand-in that records every call: which pose, with the roll free or not, and the answer.
struct RecordingSolver : PoseSolver {
  struct Call {
    Eigen::Isometry3d target;
    bool free_roll, solved;
  };
  explicit RecordingSolver(std::vector<Call>* calls, std::mutex* m) : calls(calls), m(m) {}
  bool solve(const Eigen::Isometry3d& t, const Eigen::VectorXd&, std::uint64_t, double, Eigen::VectorXd&) override {
    return record(t, false);
  }
  bool solve_free_roll(const Eigen::Isometry3d& t, const Eigen::VectorXd&, std::uint64_t, double,
                       Eigen::VectorXd&) override {
    return record(t, true);
  }
  bool record(const Eigen::Isometry3d& t, bool free) {
    const bool ok = t.translation().z() >= 0.0;
    std::lock_guard<std::mutex> lock(*m);
    calls->push_back({t, free, ok});
    return ok;
  }
  std::vector<Call>* calls;
  std::mutex* m;
};

TEST(Sweep, PlumbingAgainstAKnownSolver) {
  // With the half-space stand-in (a pose is reachable when its point has z >= 0, whatever its roll),
  // each voxel's count is the number of its (direction, roll) frames that the reach bounds let
  // through and whose point has z >= 0: an independent count. And the calls follow the sweep's
  // rules: none on a frame the bounds reject; at most one free-roll call per (voxel, direction); a
  // fixed-roll call fails only when it starts from a neighbouring voxel that solved the same frame.
  const ChainModel& m = head7();
  WorkspaceOptions o = coarse();
  o.directions = 9;
  o.any_roll = false;  // every (direction, roll) frame counts
  std::vector<RecordingSolver::Call> calls;
  std::mutex mutex;
  const ReachabilityMap map = compute_reachability(m, o, nullptr, [&](const ChainModel&, const WorkspaceOptions&) {
    return std::make_unique<RecordingSolver>(&calls, &mutex);
  });
  EXPECT_EQ(map.tried, 18);
  ASSERT_GT(map.voxel_ids.size(), 10u);
  const auto dirs = fibonacci_directions(o.directions);
  const ReachBound bound(m, o);
  const double radius = 0.5 * o.voxel_size;
  std::map<std::int64_t, std::size_t> row_of;
  for (std::size_t v = 0; v < map.voxel_ids.size(); ++v) row_of[map.voxel_ids[v]] = v;
  // Which voxel, direction and roll a call was about.
  auto locate = [&](const Eigen::Isometry3d& t, std::int64_t& k, int& di, int& r) {
    double best = 1e9;
    for (int d = 0; d < o.directions; ++d) {
      const Eigen::Vector3d c = t.translation() - radius * dirs[d];
      const Eigen::Vector3d ijk = ((c - map.grid.origin) / o.voxel_size).array() - 0.5;
      const Eigen::Vector3d rounded = ijk.array().round();
      const double err = (ijk - rounded).norm() + (t.linear().col(0) - dirs[d]).norm();
      if (err < best) {
        best = err;
        di = d;
        k = (static_cast<std::int64_t>(rounded.x()) * map.grid.n + static_cast<std::int64_t>(rounded.y())) * map.grid.n +
            static_cast<std::int64_t>(rounded.z());
      }
    }
    r = -1;
    for (int q = 0; q < o.rolls; ++q) {
      const Eigen::Isometry3d f = approach_frame(t.translation(), dirs[di], 2 * M_PI * q / o.rolls, o.approach);
      if ((f.linear() - t.linear()).norm() < 1e-9) r = q;
    }
    return best < 1e-6;
  };
  auto bit = [&](std::int64_t k, int unit) {
    const auto it = row_of.find(k);
    if (it == row_of.end()) return false;
    return ((map.reached[it->second * reached_bytes_per_voxel(map.tried) + unit / 8] >> (unit % 8)) & 1) != 0;
  };
  std::set<std::pair<std::int64_t, int>> free_calls;
  for (const auto& call : calls) {
    std::int64_t k = 0;
    int di = 0, r = 0;
    ASSERT_TRUE(locate(call.target, k, di, r)) << "a call for a pose that is no voxel's";
    ASSERT_TRUE(row_of.count(k));
    const Eigen::Vector3d p = call.target.translation();
    if (call.free_roll) {
      EXPECT_TRUE(bound.possible_any_roll(p, dirs[di]));
      EXPECT_TRUE(free_calls.emplace(k, di).second) << "two free-roll calls for one direction of a voxel";
      continue;
    }
    ASSERT_GE(r, 0);
    EXPECT_TRUE(bound.possible(call.target)) << "an IK call for a frame the reach bounds reject";
    if (!call.solved) {
      const int unit = di * o.rolls + r;
      const std::int64_t n = map.grid.n;
      bool neighbour_solved = false;
      for (std::int64_t di3 = -1; di3 <= 1; ++di3)
        for (std::int64_t dj = -1; dj <= 1; ++dj)
          for (std::int64_t dl = -1; dl <= 1; ++dl)
            if (di3 || dj || dl) neighbour_solved |= bit(k + (di3 * n + dj) * n + dl, unit);
      EXPECT_TRUE(neighbour_solved) << "a failed fixed-roll call not started from a neighbour";
    }
  }
  for (std::size_t v = 0; v < map.voxel_ids.size(); ++v) {
    const std::int64_t k = map.voxel_ids[v];
    EXPECT_LT((map.grid.centre_of(k) - map.centres.row(v).transpose()).norm(), 1e-15);
    int expected = 0, bits = 0;
    for (int di = 0; di < o.directions; ++di)
      for (int r = 0; r < o.rolls; ++r) {
        const Eigen::Vector3d p = map.grid.centre_of(k) + radius * dirs[di];
        const bool ok = p.z() >= 0 && bound.possible(approach_frame(p, dirs[di], 2 * M_PI * r / o.rolls, o.approach));
        expected += ok;
        EXPECT_EQ(bit(k, di * o.rolls + r), ok);
        bits += bit(k, di * o.rolls + r);
      }
    EXPECT_EQ(map.solved[v], expected);
    EXPECT_EQ(bits, map.solved[v]);
  }
  EXPECT_EQ(map.ik_calls, static_cast<std::int64_t>(calls.size()));
  const Eigen::VectorXd d = map.indices();
  EXPECT_GE(d.minCoeff(), 0.0);
  EXPECT_LE(d.maxCoeff(), 100.0);
}

TEST(Sweep, AnyRollCountsDirections) {
  // The paper's rule: a direction is reached when one of its rolls is. With the half-space stand-in,
  // a direction is reached when its point has z >= 0 and the bounds let one of its rolls through.
  const ChainModel& m = head7();
  WorkspaceOptions o = coarse();
  o.directions = 9;
  o.rolls = 3;
  std::atomic<long> calls{0};
  const ReachabilityMap map = compute_reachability(m, o, nullptr, half_space(&calls));
  EXPECT_EQ(map.tried, 9);
  const auto dirs = fibonacci_directions(o.directions);
  const ReachBound bound(m, o);
  for (std::size_t v = 0; v < map.voxel_ids.size(); ++v) {
    const Eigen::Vector3d c = map.grid.centre_of(map.voxel_ids[v]);
    int expected = 0;
    for (const auto& d : dirs) {
      const Eigen::Vector3d p = c + 0.5 * o.voxel_size * d;
      bool any = false;
      for (int r = 0; r < o.rolls; ++r) any |= bound.possible(approach_frame(p, d, 2 * M_PI * r / o.rolls, o.approach));
      expected += any && p.z() >= 0;
    }
    EXPECT_EQ(map.solved[v], expected);
  }
}

TEST(Sweep, IndicesWithinRangeAndIdenticalForAnyThreadCount) {
  const ChainModel& m = head7();
  WorkspaceOptions o = coarse();
  o.threads = 1;
  const ReachabilityMap one = compute_reachability(m, o);
  o.threads = 3;
  const ReachabilityMap three = compute_reachability(m, o);
  ASSERT_GT(one.voxel_ids.size(), 10u);
  EXPECT_EQ(one.voxel_ids, three.voxel_ids);
  EXPECT_EQ(one.solved, three.solved);
  EXPECT_EQ(three.threads_used, 3);
  const Eigen::VectorXd d = one.indices();
  EXPECT_GE(d.minCoeff(), 0.0);
  EXPECT_LE(d.maxCoeff(), 100.0);
  EXPECT_GT(d.maxCoeff(), 0.0);  // TRAC-IK solves something
  // Every voxel centre is inside the grid and within reach (the hull lies within reach).
  for (Eigen::Index v = 0; v < one.centres.rows(); ++v) EXPECT_LE(one.centres.row(v).norm(), m.reach());
}

TEST(Sweep, ShardsMergeExactly) {
  const ChainModel& m = head7();
  WorkspaceOptions o = coarse();
  const ReachabilityMap whole = compute_reachability(m, o);
  std::vector<ReachabilityMap> shards;
  for (int i = 0; i < 3; ++i) {
    WorkspaceOptions s = o;
    s.shard_index = i;
    s.shard_count = 3;
    shards.push_back(compute_reachability(m, s));
  }
  const ReachabilityMap merged = merge_shards({shards[2], shards[0], shards[1]});
  EXPECT_EQ(merged.voxel_ids, whole.voxel_ids);
  EXPECT_EQ(merged.solved, whole.solved);
  EXPECT_EQ(merged.centres, whole.centres);
  EXPECT_EQ(merged.reached, whole.reached);
  EXPECT_EQ(merged.options.shard_count, 1);
  EXPECT_THROW(merge_shards({shards[0], shards[1]}), InputError);             // one missing
  EXPECT_THROW(merge_shards({shards[0], shards[1], shards[1]}), InputError);  // one twice
  WorkspaceOptions other = o;
  other.seed = 8;
  other.shard_index = 2;
  other.shard_count = 3;
  EXPECT_THROW(merge_shards({shards[0], shards[1], compute_reachability(m, other)}), InputError);
}

TEST(Sweep, VoxelsInsideTheBoundaryOrTheConvexHull) {
  // The map's voxels are exactly the grid voxels whose centre lies inside the chosen hull of the
  // seed's cloud; the boundary's voxels are among the convex hull's, and fewer.
  const ChainModel& m = head7();
  WorkspaceOptions o = coarse();
  o.voxel_size = 0.1;
  std::atomic<long> calls{0};
  o.hull = HullKind::Convex;
  const ReachabilityMap convex = compute_reachability(m, o, nullptr, half_space(&calls));
  o.hull = HullKind::Boundary;
  const ReachabilityMap boundary = compute_reachability(m, o, nullptr, half_space(&calls));
  const auto cloud = sample_tip_positions(m, o.cloud_samples, o.seed);
  const ConvexHull hull = ConvexHull::of(cloud);
  const AlphaShape shape = AlphaShape::boundary(cloud, 0.5);
  std::vector<std::int64_t> in_hull, in_shape;
  for (std::int64_t k = 0; k < convex.grid.count(); ++k) {
    if (hull.contains(convex.grid.centre_of(k))) in_hull.push_back(k);
    if (shape.contains(convex.grid.centre_of(k))) in_shape.push_back(k);
  }
  EXPECT_EQ(convex.voxel_ids, in_hull);
  EXPECT_EQ(boundary.voxel_ids, in_shape);
  EXPECT_TRUE(std::includes(in_hull.begin(), in_hull.end(), in_shape.begin(), in_shape.end()));
  EXPECT_LT(in_shape.size(), in_hull.size());
  EXPECT_GT(in_shape.size(), in_hull.size() / 2);
  EXPECT_EQ(boundary.alpha, shape.alpha());
  EXPECT_TRUE(std::isinf(convex.alpha));
  EXPECT_EQ(boundary.hull_voxels, static_cast<std::int64_t>(in_shape.size()));
  WorkspaceOptions bad = o;
  bad.shrink = 1.5;
  EXPECT_THROW(compute_reachability(m, bad), InputError);
  EXPECT_EQ(parse_hull_kind("convex"), HullKind::Convex);
  EXPECT_THROW(parse_hull_kind("concave"), InputError);
}

TEST(Sweep, ReachedBitsAgreeWithTheCounts) {
  const ChainModel& m = head7();
  for (bool any_roll : {true, false}) {
    WorkspaceOptions o = coarse();
    o.any_roll = any_roll;
    const ReachabilityMap map = compute_reachability(m, o);
    const int bytes = reached_bytes_per_voxel(map.tried);
    ASSERT_EQ(map.reached.size(), map.voxel_ids.size() * bytes);
    for (std::size_t v = 0; v < map.voxel_ids.size(); ++v) {
      int count = 0;
      for (int u = 0; u < bytes * 8; ++u) {
        const bool on = (map.reached[v * bytes + u / 8] >> (u % 8)) & 1;
        if (u >= map.tried) EXPECT_FALSE(on) << "a bit beyond the units";
        count += on;
      }
      EXPECT_EQ(count, map.solved[v]);
    }
  }
}

TEST(Sweep, BadOptionsAreInputErrors) {
  const ChainModel& m = head7();
  auto bad = [&](auto edit) {
    WorkspaceOptions o = coarse();
    edit(o);
    EXPECT_THROW(compute_reachability(m, o), InputError);
  };
  bad([](WorkspaceOptions& o) { o.voxel_size = 0; });
  bad([](WorkspaceOptions& o) { o.voxel_size = -0.1; });
  bad([](WorkspaceOptions& o) { o.voxel_size = std::nan(""); });
  bad([](WorkspaceOptions& o) { o.directions = 0; });
  bad([](WorkspaceOptions& o) { o.rolls = 0; });
  bad([](WorkspaceOptions& o) { o.timeout = 0; });
  bad([](WorkspaceOptions& o) { o.epsilon = -1; });
  bad([](WorkspaceOptions& o) { o.cloud_samples = 3; });
  bad([](WorkspaceOptions& o) { o.threads = -2; });
  bad([](WorkspaceOptions& o) { o.shard_index = 3, o.shard_count = 3; });
  bad([](WorkspaceOptions& o) { o.shard_count = 0; });
  WorkspaceOptions free_roll = coarse();
  free_roll.rolls = 0;  // rolls do not matter with a free roll
  free_roll.free_roll = true;
  EXPECT_NO_THROW(free_roll.validate());
}

TEST(Sweep, ProgressReportsAndCancels) {
  const ChainModel& m = head7();
  WorkspaceOptions o = coarse();
  std::atomic<long> calls{0};
  std::int64_t last_done = -1, last_total = -1;
  compute_reachability(m, o, [&](std::int64_t done, std::int64_t total) {
    EXPECT_GE(done, last_done);
    last_done = done;
    last_total = total;
    return true;
  }, half_space(&calls));
  EXPECT_EQ(last_done, last_total);
  EXPECT_GT(last_total, 0);
  o.timeout = 0.02;  // slow enough that cancelling comes before the end
  EXPECT_THROW(compute_reachability(m, o, [](std::int64_t, std::int64_t) { return false; }), Cancelled);
}

TEST(Npz, Crc32AndLayout) {
  const char* check = "123456789";
  EXPECT_EQ(crc32(check, 9), 0xCBF43926U);  // the standard check value of CRC-32/ISO-HDLC
  EXPECT_EQ(crc32(check + 4, 5, crc32(check, 4)), 0xCBF43926U);
  NpzWriter w;
  w.add_f64("a", {1.0, 2.0, 3.0, 4.0, 5.0, 6.0}, {2, 3});
  w.add_string("s", "héllo");
  const std::string z = w.bytes();
  EXPECT_EQ(z.substr(0, 4), std::string("PK\x03\x04", 4));
  // The first entry's NPY data starts after a 64-byte aligned header.
  const std::size_t npy = z.find("\x93NUMPY");
  ASSERT_NE(npy, std::string::npos);
  const std::size_t header_len = static_cast<unsigned char>(z[npy + 8]) | (static_cast<unsigned char>(z[npy + 9]) << 8);
  EXPECT_EQ((10 + header_len) % 64, 0u);
  EXPECT_NE(z.find("'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), }"), std::string::npos);
  EXPECT_NE(z.find("'descr': '<U5'"), std::string::npos);
  EXPECT_THROW(w.add_f64("b", {1.0, 2.0}, {3}), std::invalid_argument);
  EXPECT_THROW(w.write("/nonexistent-dir/x.npz"), std::runtime_error);
}

TEST(Npz, SaveMapAndUnwritablePath) {
  const ChainModel& m = head7();
  std::atomic<long> calls{0};
  const ReachabilityMap map = compute_reachability(m, coarse(), nullptr, half_space(&calls));
  const std::string path = ::testing::TempDir() + "/snakehead_map_test.npz";
  save_npz(map, path, "test");
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  const std::string bytes = ss.str();
  EXPECT_GT(bytes.size(), 1000u);
  EXPECT_NE(bytes.find("centers.npy"), std::string::npos);
  EXPECT_NE(bytes.find("chain_hash.npy"), std::string::npos);
  for (const char* key : {"reached.npy", "sphere_directions.npy", "hull.npy", "shrink.npy", "alpha.npy"})
    EXPECT_NE(bytes.find(key), std::string::npos) << key;
  std::remove(path.c_str());
  EXPECT_THROW(save_npz(map, "/nonexistent-dir/map.npz", "test"), InputError);
  // An inconsistent map is refused before anything is written.
  ReachabilityMap bad = map;
  bad.reached.pop_back();
  EXPECT_THROW(save_npz(bad, path, "test"), InputError);
  bad = map;
  bad.solved.pop_back();
  EXPECT_THROW(save_npz(bad, path, "test"), InputError);
  std::ifstream none(path);
  EXPECT_FALSE(none.good());
}
