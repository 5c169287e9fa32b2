// Hostile and broken input (issue 14): durations that would overflow a clock deadline, sizes that would
// exhaust memory, robot descriptions that would crash urdfdom's parser or lose data silently, urdfdom's
// console output, and files that must survive a failed write. Every case is an InputError whose message
// says what was wrong, never a crash, a hang or a silently wrong answer.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <dirent.h>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <thread>

#include "snakehead/kinematics.hpp"
#include "snakehead/limits.hpp"
#include "snakehead/npz.hpp"
#include "snakehead/trac_ik.hpp"
#include "snakehead/workspace.hpp"

using namespace snakehead;

namespace {

const std::string kSnake = std::string(SNAKEHEAD_URDF_DIR) + "/snake16.urdf";

std::shared_ptr<const ChainModel> head7() {
  static auto m = std::make_shared<const ChainModel>(ChainModel::from_urdf(kSnake, "neck_end", "head_tip"));
  return m;
}

// Runs `fn`, which must throw InputError; returns its message ("" and a test failure otherwise).
template <class Fn>
std::string input_error(Fn fn) {
  try {
    fn();
  } catch (const InputError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected InputError, got another exception: " << e.what();
    return "";
  }
  ADD_FAILURE() << "expected InputError, nothing was thrown";
  return "";
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace

// ---------------------------------------------------------------------------------------------------------
// Durations: a finite but huge timeout overflowed the steady_clock deadline (64-bit ns), so every call
// gave up at once and reachable targets were reported unreachable.

TEST(HostileTimeout, HugeTimeoutsAreRejectedNamingTheField) {
  const auto model = head7();
  const Eigen::VectorXd q0 = Eigen::VectorXd::Zero(model->n_joints());
  const Eigen::Isometry3d target = forward_kinematics(*model, Eigen::VectorXd::Constant(model->n_joints(), 0.2));
  for (double t : {86400.5, 1e9, 1e10, 1e19, 1e300, std::numeric_limits<double>::max()}) {
    SCOPED_TRACE(t);
    TracIKOptions o;
    o.timeout = t;
    std::string msg = input_error([&] { check_options(o); });
    EXPECT_TRUE(contains(msg, "timeout") && contains(msg, "86400")) << msg;
    msg = input_error([&] { TracIK(model, o); });
    EXPECT_TRUE(contains(msg, "timeout")) << msg;
    TracIK ik(model);
    input_error([&] { ik.solve_ex(target, q0, o); });
    Eigen::VectorXd q;
    msg = input_error([&] { kdl_nr_jl_ik(*model, target, q0, q, t); });
    EXPECT_TRUE(contains(msg, "timeout")) << msg;
    WorkspaceOptions w;
    w.timeout = t;
    msg = input_error([&] { w.validate(); });
    EXPECT_TRUE(contains(msg, "timeout") && contains(msg, "86400")) << msg;
  }
}

TEST(HostileTimeout, LongestAllowedTimeoutStillSolves) {
  // A day-long budget: the deadline is far away, so a reachable target is found (Speed returns at the
  // first solution), seeded or not; before the fix a seeded call's guard (10 x timeout) overflowed at 1e9 s.
  const auto model = head7();
  const Eigen::VectorXd q0 = Eigen::VectorXd::Zero(model->n_joints());
  const Eigen::Isometry3d target = forward_kinematics(*model, Eigen::VectorXd::Constant(model->n_joints(), 0.3));
  for (bool seeded : {false, true}) {
    TracIKOptions o;
    o.timeout = limits::kMaxTimeoutSeconds;
    if (seeded) o.seed = 3;
    TracIK ik(model, o);
    Eigen::VectorXd q;
    EXPECT_TRUE(ik.solve(target, q0, q)) << "seeded " << seeded;
  }
  Eigen::VectorXd q;
  Eigen::VectorXd near = Eigen::VectorXd::Constant(model->n_joints(), 0.28);
  EXPECT_TRUE(kdl_nr_jl_ik(*model, target, near, q, limits::kMaxTimeoutSeconds));
}

TEST(HostileTimeout, DeadlinesSaturateInsteadOfOverflowing) {
  using Clock = std::chrono::steady_clock;
  const auto now = Clock::now();
  EXPECT_EQ(deadline_after(now, 1e300), Clock::time_point::max());
  EXPECT_EQ(deadline_after(now, 1e10), Clock::time_point::max());
  EXPECT_EQ(deadline_after(now, std::numeric_limits<double>::infinity()), Clock::time_point::max());
  EXPECT_EQ(deadline_after(now, 0.0), now);
  EXPECT_EQ(deadline_after(now, -5.0), now);
  EXPECT_EQ(deadline_after(now, std::nan("")), now);  // never "no deadline" by accident
  const auto day = deadline_after(now, 86400.0);
  EXPECT_NEAR(std::chrono::duration<double>(day - now).count(), 86400.0, 1e-6);
  EXPECT_GT(deadline_after(now, 1e9), now);
}

// ---------------------------------------------------------------------------------------------------------
// Sizes: numbers that become allocations are bounded before anything is allocated, with a message that
// names the field and the limit (a voxel of 1e-9 m asked for 10^27 voxels; directions x rolls overflowed int).

TEST(HostileSizes, SweepOptionsBeyondTheirLimitsNameFieldAndLimit) {
  auto message = [](auto edit) {
    WorkspaceOptions o;
    edit(o);
    return input_error([&] { o.validate(); });
  };
  std::string m = message([](WorkspaceOptions& o) { o.directions = 1'000'000'000; });
  EXPECT_TRUE(contains(m, "directions") && contains(m, std::to_string(limits::kMaxDirections))) << m;
  m = message([](WorkspaceOptions& o) { o.rolls = 1'000'000; });
  EXPECT_TRUE(contains(m, "rolls") && contains(m, std::to_string(limits::kMaxRolls))) << m;
  m = message([](WorkspaceOptions& o) { o.directions = 100'000, o.rolls = 100'000; });  // the product overflowed int
  EXPECT_TRUE(contains(m, "directions")) << m;
  m = message([](WorkspaceOptions& o) { o.directions = 1000, o.rolls = 100; });
  EXPECT_TRUE(contains(m, "frames per voxel") && contains(m, std::to_string(limits::kMaxFramesPerVoxel))) << m;
  m = message([](WorkspaceOptions& o) { o.cloud_samples = 2'000'000'000; });
  EXPECT_TRUE(contains(m, "cloud_samples") && contains(m, std::to_string(limits::kMaxCloudSamples))) << m;
  m = message([](WorkspaceOptions& o) { o.threads = 1'000'000; });
  EXPECT_TRUE(contains(m, "threads") && contains(m, std::to_string(limits::kMaxThreads))) << m;
  // A tiny voxel passes here (the grid depends on the chain; see below). Free roll: rolls do not count.
  WorkspaceOptions free_roll;
  free_roll.free_roll = true;
  free_roll.rolls = 1'000'000;
  free_roll.directions = limits::kMaxDirections;
  EXPECT_NO_THROW(free_roll.validate());
}

TEST(HostileSizes, TinyVoxelsAreRejectedBeforeTheSweep) {
  const auto model = head7();
  WorkspaceOptions o;
  o.cloud_samples = 200;
  for (double voxel : {1e-9, 1e-300, 2.0 * model->reach() / (limits::kMaxVoxelsPerAxis + 1)}) {
    o.voxel_size = voxel;
    const std::string m = input_error([&] { compute_reachability(*model, o); });
    EXPECT_TRUE(contains(m, "voxel size") && contains(m, std::to_string(limits::kMaxVoxelsPerAxis))) << m;
  }
  EXPECT_NO_THROW(VoxelGrid::around(Eigen::Vector3d::Zero(), 1.0, 1.0 / limits::kMaxVoxelsPerAxis));
  std::string m = input_error([&] { fibonacci_directions(2'000'000'000); });
  EXPECT_TRUE(contains(m, std::to_string(limits::kMaxDirections))) << m;
  m = input_error([&] { sample_tip_positions(*model, 2'000'000'000, 1); });
  EXPECT_TRUE(contains(m, std::to_string(limits::kMaxCloudSamples))) << m;
}
