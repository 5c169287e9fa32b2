// The workspace sweep (Algorithm 1): geometry helpers, the hull, cheap exits, determinism across
// thread counts, shards, the .npz writer and bad input.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdio>
#include <fstream>
#include <random>
#include <set>
#include <sstream>

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
  bool solve(const Eigen::Isometry3d& target, const Eigen::VectorXd&, std::uint64_t, Eigen::VectorXd&) override {
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

TEST(Sweep, PlumbingAgainstAKnownSolver) {
  // With the half-space stand-in, each voxel's count is the number of its sphere points with z >= 0
  // (times the rolls) among those the reach bounds let through: an independent count.
  const ChainModel& m = head7();
  WorkspaceOptions o = coarse();
  o.directions = 9;
  o.any_roll = false;  // every (direction, roll) frame counts
  std::atomic<long> calls{0};
  const ReachabilityMap map = compute_reachability(m, o, nullptr, half_space(&calls));
  EXPECT_EQ(map.tried, 18);
  ASSERT_GT(map.voxel_ids.size(), 10u);
  const auto dirs = fibonacci_directions(o.directions);
  const ReachBound bound(m, o);
  // Calls: one per pose the bounds let through, plus a second chance for each failed pose whose
  // neighbour in +z (the next voxel of its run) solved the same pose.
  auto pose_ok = [&](std::int64_t k, const Eigen::Vector3d& d, int r, bool& possible) {
    const Eigen::Vector3d p = map.grid.centre_of(k) + 0.5 * o.voxel_size * d;
    possible = bound.possible(approach_frame(p, d, 2 * M_PI * r / o.rolls, o.approach));
    return possible && p.z() >= 0;
  };
  const std::set<std::int64_t> ids(map.voxel_ids.begin(), map.voxel_ids.end());
  long expected_calls = 0;
  for (std::size_t v = 0; v < map.voxel_ids.size(); ++v) {
    const std::int64_t k = map.voxel_ids[v];
    EXPECT_LT((map.grid.centre_of(k) - map.centres.row(v).transpose()).norm(), 1e-15);
    const bool has_next = (k + 1) % map.grid.n != 0 && ids.count(k + 1);
    int expected = 0;
    for (const auto& d : dirs)
      for (int r = 0; r < o.rolls; ++r) {
        bool possible = false, next_possible = false;
        const bool ok = pose_ok(k, d, r, possible);
        expected += ok;
        expected_calls += possible;
        if (possible && !ok && has_next && pose_ok(k + 1, d, r, next_possible)) ++expected_calls;
      }
    EXPECT_EQ(map.solved[v], expected);
  }
  EXPECT_EQ(calls.load(), expected_calls);
  EXPECT_EQ(map.ik_calls, expected_calls);
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
  EXPECT_EQ(merged.options.shard_count, 1);
  EXPECT_THROW(merge_shards({shards[0], shards[1]}), InputError);             // one missing
  EXPECT_THROW(merge_shards({shards[0], shards[1], shards[1]}), InputError);  // one twice
  WorkspaceOptions other = o;
  other.seed = 8;
  other.shard_index = 2;
  other.shard_count = 3;
  EXPECT_THROW(merge_shards({shards[0], shards[1], compute_reachability(m, other)}), InputError);
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
  std::remove(path.c_str());
  EXPECT_THROW(save_npz(map, "/nonexistent-dir/map.npz", "test"), InputError);
}
