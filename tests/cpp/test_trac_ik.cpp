// TRAC-IK and its pose error: derivatives against finite differences, solutions checked with KDL's own FK,
// solve types, free roll, seeded determinism, many threads on one solver, a forked child, timeouts, bad input.
#include <gtest/gtest.h>

#include <chrono>
#include <random>
#include <thread>

#include <sys/wait.h>
#include <unistd.h>

#include "snakehead/core_threads.hpp"
#include "snakehead/kinematics.hpp"
#include "snakehead/limits.hpp"
#include "snakehead/pose_error.hpp"
#include "snakehead/trac_ik.hpp"

using namespace snakehead;

namespace {

const std::string kSnake = std::string(SNAKEHEAD_URDF_DIR) + "/snake16.urdf";

// Wall-clock budgets: a build with sanitizers (SNAKEHEAD_SANITIZE) runs tens of times slower (trac_ik.cpp).
#ifdef SNAKEHEAD_SANITIZE
constexpr double kClockScale = 30.0;
#else
constexpr double kClockScale = 1.0;
#endif

std::shared_ptr<const ChainModel> head7() {
  static auto m = std::make_shared<const ChainModel>(ChainModel::from_urdf(kSnake, "neck_end", "head_tip"));
  return m;
}
std::shared_ptr<const ChainModel> head6() {
  static auto m = std::make_shared<const ChainModel>(ChainModel::from_urdf(kSnake, "link_10", "head_tip"));
  return m;
}

Eigen::VectorXd random_q(const ChainModel& m, std::mt19937& rng) {
  Eigen::VectorXd q(m.n_joints());
  for (int i = 0; i < m.n_joints(); ++i) q[i] = std::uniform_real_distribution<double>(m.lower()[i], m.upper()[i])(rng);
  return q;
}

Eigen::Matrix3d random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> g;
  Eigen::Quaterniond q(g(rng), g(rng), g(rng), g(rng));
  return q.normalized().toRotationMatrix();
}

// An independent check of a solution: KDL's FK, the limits, and the error measured without pose_error.hpp
// (position distance, and the rotation angle from the trace), which bounds every axis of the twist.
void expect_solution(const ChainModel& m, const Eigen::Isometry3d& target, const Eigen::VectorXd& q, double eps) {
  ASSERT_EQ(q.size(), m.n_joints());
  for (int i = 0; i < q.size(); ++i) {
    EXPECT_GE(q[i], m.lower()[i]);
    EXPECT_LE(q[i], m.upper()[i]);
  }
  const Eigen::Isometry3d f = kdl_forward_kinematics(m, q);
  EXPECT_LE((f.translation() - target.translation()).norm(), std::sqrt(3.0) * eps * (1 + 1e-9));
  const double c = std::clamp(((target.linear().transpose() * f.linear()).trace() - 1) / 2, -1.0, 1.0);
  EXPECT_LE(std::acos(c), std::sqrt(3.0) * eps * (1 + 1e-6) + 1e-7);
}

using Poses = std::vector<Eigen::Isometry3d, Eigen::aligned_allocator<Eigen::Isometry3d>>;

// T reachable targets (the poses of random configurations) and T random starts (columns of q0), drawn in turn.
void random_batch(const ChainModel& m, std::mt19937& rng, int T, Poses& targets, Eigen::MatrixXd& q0) {
  q0.resize(m.n_joints(), T);
  for (int k = 0; k < T; ++k) {
    targets.push_back(forward_kinematics(m, random_q(m, rng)));
    q0.col(k) = random_q(m, rng);
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------
// The pose error.

TEST(PoseError, LogIsTheInverseOfTheExponential) {
  std::mt19937 rng(1);
  for (int k = 0; k < 200; ++k) {
    const Eigen::Matrix3d R = random_rotation(rng);
    const Eigen::Vector3d w = rotation_log(R);
    EXPECT_LE(w.norm(), M_PI + 1e-12);
    const Eigen::Matrix3d back = w.norm() > 0 ? Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix()
                                              : Eigen::Matrix3d::Identity();
    EXPECT_LT((back - R).cwiseAbs().maxCoeff(), 1e-12);
  }
  // Near pi and at tiny angles.
  for (double a : {M_PI, M_PI - 1e-9, 1e-10, 0.0}) {
    const Eigen::Vector3d axis = Eigen::Vector3d(1, -2, 0.5).normalized();
    const Eigen::Vector3d w = rotation_log(Eigen::AngleAxisd(a, axis).toRotationMatrix());
    EXPECT_NEAR(w.norm(), a, 1e-12);
    if (a > 0) EXPECT_NEAR(std::abs(w.normalized().dot(axis)), 1.0, 1e-9);
  }
}

TEST(PoseError, ErrorIsInTheTargetFrame) {
  Eigen::Isometry3d target = Eigen::Isometry3d::Identity();
  target.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  target.translation() << 1, 2, 3;
  Eigen::Isometry3d cur = target;
  cur.translation() += Eigen::Vector3d(0, 0.1, 0);                        // base +y = target's +x
  cur.linear() = cur.linear() * Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitX()).toRotationMatrix();  // roll
  const Vector6d e = pose_error(target, cur);
  Vector6d want;
  want << 0.1, 0, 0, 0.2, 0, 0;
  EXPECT_LT((e - want).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(PoseError, DeadZoneResidual) {
  Vector6d e, b;
  e << 0.3, -0.3, 0.05, -2.0, 1e-3, -1e-3;
  b << 0.1, 0.1, 0.1, std::numeric_limits<double>::infinity(), 0, 0;
  const Vector6d r = bounded_residual(e, b);
  Vector6d want;
  want << 0.2, -0.2, 0, 0, 1e-3, -1e-3;
  EXPECT_LT((r - want).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_FALSE(pose_reached(e, b, 1e-4));
  e[4] = e[5] = 5e-5;
  e[0] = e[1] = 0.1 + 5e-5;
  EXPECT_TRUE(pose_reached(e, b, 1e-4));
  e[2] = std::nan("");
  EXPECT_FALSE(pose_reached(e, b, 1e-4));
}

TEST(PoseError, JacobianMatchesFiniteDifferences) {
  const auto& m = *head7();
  std::mt19937 rng(2);
  Matrix6Xd jac(6, m.n_joints()), dr(6, m.n_joints());
  Vector6d bounds;
  bounds << 0, 0, 0, 0, 0, 0;
  int checked = 0;
  for (int k = 0; k < 50; ++k) {
    const Eigen::VectorXd q = random_q(m, rng);
    const Eigen::Isometry3d target = forward_kinematics(m, random_q(m, rng));
    Eigen::Isometry3d tip;
    tip_jacobian(m, q, jac, tip);
    Vector6d r;
    residual_and_jacobian(target, tip, jac, bounds, r, dr);
    if (r.tail<3>().norm() > 3.0) continue;  // the log jumps at pi; stay clear of it
    ++checked;
    const double h = 1e-6;
    for (int j = 0; j < m.n_joints(); ++j) {
      Eigen::VectorXd qp = q, qm = q;
      qp[j] += h;
      qm[j] -= h;
      const Vector6d fd = (pose_error(target, forward_kinematics(m, qp)) - pose_error(target, forward_kinematics(m, qm))) /
                          (2 * h);
      EXPECT_LT((fd - dr.col(j)).cwiseAbs().maxCoeff(), 1e-6) << "joint " << j << " sample " << k;
    }
  }
  EXPECT_GE(checked, 35);
  // Inside a dead zone the residual is flat: open rotation bounds zero those rows.
  bounds.tail<3>().setConstant(std::numeric_limits<double>::infinity());
  const Eigen::VectorXd q = random_q(m, rng);
  Eigen::Isometry3d tip;
  tip_jacobian(m, q, jac, tip);
  Vector6d r;
  residual_and_jacobian(forward_kinematics(m, random_q(m, rng)), tip, jac, bounds, r, dr);
  EXPECT_EQ(r.tail<3>(), Eigen::Vector3d::Zero());
  EXPECT_EQ(dr.bottomRows<3>().cwiseAbs().maxCoeff(), 0.0);
  EXPECT_GT(dr.topRows<3>().cwiseAbs().maxCoeff(), 0.0);
}

// ---------------------------------------------------------------------------------------------------------
// Solving.

TEST(TracIK, SolvesReachableTargetsWithEveryAlgorithm) {
  for (auto model : {head6(), head7()}) {
    TracIKOptions o;
    o.timeout = 0.02;
    TracIK ik(model, o);
    std::mt19937 rng(3);
    for (IKAlgorithm alg : {IKAlgorithm::TracIK, IKAlgorithm::KdlRR, IKAlgorithm::Sqp}) {
      int solved = 0;
      for (int k = 0; k < 40; ++k) {
        const Eigen::Isometry3d target = forward_kinematics(*model, random_q(*model, rng));
        o.seed = 300 + k;  // seeded: bounded by evaluations, so the count is the same on a loaded machine
        const IKResult r = ik.solve_ex(target, random_q(*model, rng), o, alg);
        if (!r.found) continue;
        ++solved;
        expect_solution(*model, target, r.q, o.epsilon);
        EXPECT_TRUE(pose_reached(r.error, o.bounds, o.epsilon));
      }
      EXPECT_GE(solved, 38) << "algorithm " << static_cast<int>(alg) << ", " << model->n_joints() << " joints";
    }
  }
}

TEST(TracIK, ARacedCallsSqpHalfMayOutliveTheSolverAndItsModel) {
  // Distance races both halves to the timeout; the SQP half on the worker pool stops at its next evaluation, which may
  // come after the solver (and the only other owner of its model) is gone: it holds the model itself.
  std::mt19937 rng(12);
  for (int k = 0; k < 20; ++k) {
    auto model = std::make_shared<const ChainModel>(ChainModel::from_urdf(kSnake, "neck_end", "head_tip"));
    const Eigen::Isometry3d target = forward_kinematics(*model, random_q(*model, rng));
    const Eigen::VectorXd q0 = random_q(*model, rng);
    TracIKOptions o;
    o.timeout = 0.002;
    o.solve_type = SolveType::Distance;
    auto ik = std::make_unique<TracIK>(std::move(model), o);
    const IKResult r = ik->solve_ex(target, q0, o);
    ik.reset();
    EXPECT_EQ(r.q.size(), 7);
  }
}

TEST(TracIK, EverySolveTypeSolvesAndRanksItsSolutions) {
  const auto model = head7();
  std::mt19937 rng(4);
  for (int k = 0; k < 6; ++k) {
    const Eigen::Isometry3d target = forward_kinematics(*model, random_q(*model, rng));
    const Eigen::VectorXd q0 = random_q(*model, rng);
    // The same seed gives every solve type the same search up to the first solution (Speed's answer);
    // the others keep going and keep the best, so they can only do as well or better.
    TracIKOptions o;
    o.timeout = 0.003;
    o.seed = 100 + k;
    const IKResult speed = TracIK(model, o).solve_ex(target, q0, o);
    ASSERT_TRUE(speed.found);
    expect_solution(*model, target, speed.q, o.epsilon);
    Matrix6Xd J;
    Eigen::Isometry3d tip;
    auto measures = [&](const Eigen::VectorXd& q) {
      tip_jacobian(*model, q, J, tip);
      Eigen::JacobiSVD<Eigen::MatrixXd> svd(J);
      const auto s = svd.singularValues();
      const double m1 = std::sqrt((J * J.transpose()).determinant());
      return std::make_pair(m1, s[s.size() - 1] / s[0]);
    };
    for (SolveType t : {SolveType::Distance, SolveType::Manip1, SolveType::Manip2}) {
      o.solve_type = t;
      const IKResult r = TracIK(model, o).solve_ex(target, q0, o);
      ASSERT_TRUE(r.found) << to_string(t);
      expect_solution(*model, target, r.q, o.epsilon);
      EXPECT_GE(r.solutions, 1);
      if (t == SolveType::Distance) EXPECT_LE((r.q - q0).norm(), (speed.q - q0).norm() + 1e-12);
      if (t == SolveType::Manip1) EXPECT_GE(measures(r.q).first, measures(speed.q).first * (1 - 1e-9));
      if (t == SolveType::Manip2) EXPECT_GE(measures(r.q).second, measures(speed.q).second * (1 - 1e-9));
    }
    o.solve_type = SolveType::Speed;
  }
}

TEST(TracIK, DistanceUnseededIsNoFartherThanSpeed) {
  // Without a seed: the Distance search includes the Newton descent from q_init, as Speed's inline attempt
  // does, so when Speed's answer comes from that descent Distance cannot be farther.
  const auto model = head7();
  TracIKOptions o;
  o.timeout = 0.05 * kClockScale;  // long enough that a busy machine cannot cut Distance's first descent short
  TracIK speed(model, o);
  o.solve_type = SolveType::Distance;
  TracIK dist(model, o);
  std::mt19937 rng(5);
  for (int k = 0; k < 10; ++k) {
    const Eigen::VectorXd qt = random_q(*model, rng);
    const Eigen::Isometry3d target = forward_kinematics(*model, qt);
    Eigen::VectorXd q0 = qt;  // a start near a solution: the first descent finds it
    for (int i = 0; i < q0.size(); ++i) q0[i] = std::clamp(q0[i] + 0.05, model->lower()[i], model->upper()[i]);
    Eigen::VectorXd qs, qd;
    ASSERT_TRUE(speed.solve(target, q0, qs));
    ASSERT_TRUE(dist.solve(target, q0, qd));
    EXPECT_LE((qd - q0).norm(), (qs - q0).norm() + 1e-9);
  }
}

TEST(TracIK, FreeRollMatchesPositionAndXAxis) {
  for (auto model : {head6(), head7()}) {
    TracIKOptions o;
    o.timeout = 0.03;
    o.seed = 6;  // seeded: bounded by evaluations, so the count is the same on a loaded machine
    o.bounds << 0, 0, 0, std::numeric_limits<double>::infinity(), 0, 0;
    TracIK ik(model, o);
    std::mt19937 rng(6);
    int rolled = 0, solved = 0;
    for (int k = 0; k < 30; ++k) {
      Eigen::Isometry3d target = forward_kinematics(*model, random_q(*model, rng));
      // Roll the target about its own x-axis: position and x-axis stay reachable, the roll may not be.
      const double roll = std::uniform_real_distribution<double>(-M_PI, M_PI)(rng);
      target.linear() = target.linear() * Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()).toRotationMatrix();
      Eigen::VectorXd q;
      if (!ik.solve(target, random_q(*model, rng), q)) continue;
      ++solved;
      const Eigen::Isometry3d f = kdl_forward_kinematics(*model, q);
      EXPECT_LE((f.translation() - target.translation()).norm(), std::sqrt(3.0) * o.epsilon);
      const Eigen::Vector3d x = f.linear().col(0), xt = target.linear().col(0);
      EXPECT_LE(std::acos(std::clamp(x.dot(xt), -1.0, 1.0)), 2 * o.epsilon + 1e-7);
      // How far the roll ended up from the target's: left free, it is generally not matched.
      const Eigen::Vector3d y = f.linear().col(1), yt = target.linear().col(1);
      if (std::acos(std::clamp(y.dot(yt), -1.0, 1.0)) > 1e-3) ++rolled;
    }
    EXPECT_GE(solved, 29);
    EXPECT_GE(rolled, 10) << "the roll about x does not look free";
  }
}

TEST(TracIK, PerCallBoundsLoosenAnAxis) {
  const auto model = head7();
  TracIKOptions o;
  TracIK ik(model, o);
  std::mt19937 rng(7);
  const Eigen::VectorXd qt = random_q(*model, rng);
  Eigen::Isometry3d target = forward_kinematics(*model, qt);
  target.translation().x() += 0.01;  // may be unreachable exactly; 2 cm of x tolerance makes qt itself a solution
  Vector6d b = Vector6d::Zero();
  b[0] = b[1] = b[2] = 0.02;
  Eigen::VectorXd q;
  ASSERT_TRUE(ik.solve(target, qt, b, q));
  const Vector6d e = pose_error(target, forward_kinematics(*model, q));
  EXPECT_TRUE(pose_reached(e, b, o.epsilon));
  EXPECT_LE(e.head<3>().cwiseAbs().maxCoeff(), 0.02 + o.epsilon);
}

TEST(TracIK, SeededCallsAreReproducible) {
  const auto model = head6();
  std::mt19937 rng(8);
  for (SolveType t : {SolveType::Speed, SolveType::Distance}) {
    TracIKOptions o;
    o.timeout = 0.002;
    o.seed = 12345;
    o.solve_type = t;
    TracIK a(model, o), b(model, o);
    for (int k = 0; k < 10; ++k) {
      const Eigen::Isometry3d target = forward_kinematics(*model, random_q(*model, rng));
      const Eigen::VectorXd q0 = random_q(*model, rng);
      const IKResult r1 = a.solve_ex(target, q0, o), r2 = a.solve_ex(target, q0, o), r3 = b.solve_ex(target, q0, o);
      EXPECT_EQ(r1.found, r2.found);
      EXPECT_EQ(r1.found, r3.found);
      EXPECT_EQ(r1.q, r2.q);  // bit for bit
      EXPECT_EQ(r1.q, r3.q);
      EXPECT_EQ(r1.solutions, r2.solutions);
    }
  }
}

TEST(TracIK, ManyThreadsShareOneSolver) {
  // Seeded calls are pure functions of their inputs (bounded by evaluations, not by the clock), so 8 threads
  // sharing one solver must give, bit for bit, what one thread gives: no timing can make this test flaky.
  const auto model = head7();
  TracIKOptions o;
  o.timeout = 0.05;  // seeded: an evaluation budget, whatever the machine's speed
  TracIK ik(model, o);
  constexpr int kThreads = 8, kTargets = 25;
  std::vector<Eigen::Isometry3d, Eigen::aligned_allocator<Eigen::Isometry3d>> targets;
  std::vector<Eigen::VectorXd> starts;
  std::mt19937 rng(100);
  for (int k = 0; k < kThreads * kTargets; ++k) {
    targets.push_back(forward_kinematics(*model, random_q(*model, rng)));
    starts.push_back(random_q(*model, rng));
  }
  const auto options_of = [&](int k) {
    TracIKOptions ok = o;
    ok.seed = 1000 + k;
    return ok;
  };
  std::vector<IKResult> serial;
  int good = 0;
  for (int k = 0; k < kThreads * kTargets; ++k) {
    serial.push_back(ik.solve_ex(targets[k], starts[k], options_of(k)));
    good += serial.back().found &&
            pose_reached(targets[k], kdl_forward_kinematics(*model, serial.back().q), o.bounds, o.epsilon);
  }
  EXPECT_GE(good, kThreads * kTargets - 2);
  std::vector<IKResult> threaded(kThreads * kTargets);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t)
    threads.emplace_back([&, t] {
      for (int k = t; k < kThreads * kTargets; k += kThreads)
        threaded[k] = ik.solve_ex(targets[k], starts[k], options_of(k));
    });
  for (auto& th : threads) th.join();
  for (int k = 0; k < kThreads * kTargets; ++k) {
    EXPECT_EQ(threaded[k].found, serial[k].found) << "target " << k;
    EXPECT_EQ(threaded[k].q, serial[k].q) << "target " << k;  // bit for bit
  }
}

TEST(TracIK, BatchMatchesSingleCallsAndIsSeededPerTarget) {
  const auto model = head7();
  TracIKOptions o;
  o.seed = 9;
  TracIK ik(model, o);
  std::mt19937 rng(9);
  const int T = 40;
  Poses targets;
  Eigen::MatrixXd q0;
  random_batch(*model, rng, T, targets, q0);
  Eigen::MatrixXd q1, q2;
  std::vector<bool> ok1, ok2;
  ik.solve_many(targets, q0, q1, ok1);
  ik.solve_many(targets, q0, q2, ok2);
  EXPECT_EQ(ok1, ok2);
  EXPECT_EQ(q1, q2);
  int solved = 0;
  for (int k = 0; k < T; ++k) {
    if (!ok1[k]) continue;
    ++solved;
    expect_solution(*model, targets[k], q1.col(k), o.epsilon);
  }
  EXPECT_GE(solved, T - 1);
  // On one thread (core_threads.hpp), the same solutions: a seeded batch does not depend on its threads.
  const int default_threads = core_threads();
  EXPECT_GE(default_threads, 1);
  set_core_threads(1);
  EXPECT_EQ(core_threads(), 1);
  ik.solve_many(targets, q0, q2, ok2);
  set_core_threads(0);
  EXPECT_EQ(core_threads(), default_threads);
  EXPECT_EQ(ok1, ok2);
  EXPECT_EQ(q1, q2);
  EXPECT_THROW(set_core_threads(-1), InputError);
  EXPECT_THROW(set_core_threads(limits::kMaxThreads + 1), InputError);
  // Unseeded too.
  TracIK fast(model);
  fast.solve_many(targets, q0, q1, ok1);
  for (int k = 0; k < T; ++k)
    if (ok1[k]) expect_solution(*model, targets[k], q1.col(k), o.epsilon);
}

TEST(TracIK, SubsetWithItsStreamsMatchesTheWholeBatch) {
  const auto model = head7();
  TracIKOptions o;
  o.seed = 4;
  TracIK ik(model, o);
  std::mt19937 rng(4);
  const int T = 12;
  Poses targets, subset;
  Eigen::MatrixXd q0;
  random_batch(*model, rng, T, targets, q0);
  Eigen::MatrixXd q_all, q_sub, q_plain;
  std::vector<bool> ok_all, ok_sub, ok_plain;
  ik.solve_many(targets, q0, q_all, ok_all);
  const std::vector<std::uint64_t> streams{2, 5, 11};
  Eigen::MatrixXd q0_sub(model->n_joints(), 3);
  for (int i = 0; i < 3; ++i) {
    subset.push_back(targets[streams[i]]);
    q0_sub.col(i) = q0.col(static_cast<Eigen::Index>(streams[i]));
  }
  ik.solve_many(subset, q0_sub, q_sub, ok_sub, &streams);
  ik.solve_many(subset, q0_sub, q_plain, ok_plain);  // streams 0, 1, 2: other searches
  bool all_same = true;
  for (int i = 0; i < 3; ++i) {
    const auto k = static_cast<Eigen::Index>(streams[i]);
    EXPECT_EQ(ok_sub[i], ok_all[k]) << "target " << k;
    EXPECT_EQ(q_sub.col(i), q_all.col(k)) << "target " << k;  // bit for bit
    all_same = all_same && q_plain.col(i) == q_all.col(k);
  }
  EXPECT_FALSE(all_same);  // (the streams are what made the subset's answers the batch's)
  const std::vector<std::uint64_t> two{0, 1};
  EXPECT_THROW(ik.solve_many(subset, q0_sub, q_sub, ok_sub, &two), InputError);
}

// Targets of random configurations (reachable) and random starts; how many a batch solves.
int solve_batch(const TracIK& ik, std::uint32_t seed) {
  const ChainModel& m = ik.model();
  std::mt19937 rng(seed);
  const int T = 24;
  Poses targets;
  Eigen::MatrixXd q0, q;
  random_batch(m, rng, T, targets, q0);
  std::vector<bool> ok;
  ik.solve_many(targets, q0, q, ok);
  int solved = 0;
  for (int k = 0; k < T; ++k)
    solved += ok[k] && pose_reached(targets[k], kdl_forward_kinematics(m, q.col(k)), ik.options().bounds,
                                    ik.options().epsilon);
  for (int k = 0; k < 4; ++k) {  // unseeded single calls: the race hands the SQP half to a worker
    Eigen::VectorXd qk;
    solved += ik.solve(targets[k], random_q(m, rng), qk);
  }
  return solved;
}

TEST(TracIK, AForkedChildUsesAndDestroysTheParentsSolver) {
  TracIKOptions o;
  o.timeout = 0.5 * kClockScale;  // far above what these targets need: a loaded machine fails none
  auto ik = std::make_unique<TracIK>(head7(), o);
  ASSERT_EQ(solve_batch(*ik, 1), 28);  // the parent's workers exist and have worked
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {  // the child: its own workers, and a destructor that does not join the parent's
    alarm(static_cast<unsigned>(120 * kClockScale));  // hung: SIGALRM ends it, and the parent sees the signal
    const int solved = solve_batch(*ik, 2);
    ik.reset();
    _exit(solved == 28 ? 0 : 1);
  }
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  EXPECT_TRUE(WIFEXITED(status)) << "the child died of signal " << (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  EXPECT_EQ(WIFEXITED(status) ? WEXITSTATUS(status) : -1, 0);
  EXPECT_EQ(solve_batch(*ik, 3), 28);  // the parent's solver still works
}

TEST(TracIK, UnreachableTargetFailsAndASeededCallEndsOnItsBudget) {
  // (How long a call takes is measured in bench/, not asserted here.) A seeded call on an unreachable target ends
  // when its evaluation budget (timeout x kEvaluationsPerSecond = 7000 evaluations) is spent, never on the clock:
  // the same count on a loaded or sanitized machine.
  const auto model = head7();
  for (bool seeded : {false, true}) {
    TracIKOptions o;
    o.timeout = 0.01;
    if (seeded) o.seed = 1;
    TracIK ik(model, o);
    Eigen::Isometry3d far = Eigen::Isometry3d::Identity();
    far.translation() << 3.0, 0, 0;  // beyond the chain's reach
    Eigen::VectorXd q0 = Eigen::VectorXd::Zero(model->n_joints()), q;
    EXPECT_FALSE(ik.solve(far, q0, q));
    EXPECT_EQ(q, q0);
    const IKResult r = ik.solve_ex(far, q0, o);
    EXPECT_FALSE(r.found);
    if (seeded) {
      EXPECT_EQ(r.evaluations, 7000);
      EXPECT_EQ(ik.solve_ex(far, q0, o).evaluations, 7000);
    }
  }
}

TEST(TracIK, BadInputThrows) {
  const auto model = head7();
  TracIK ik(model);
  const Eigen::Isometry3d good = forward_kinematics(*model, Eigen::VectorXd::Zero(7));
  Eigen::VectorXd q;
  const Eigen::VectorXd q0 = Eigen::VectorXd::Zero(7);
  EXPECT_THROW(ik.solve(good, Eigen::VectorXd::Zero(6), q), InputError);
  Eigen::VectorXd out_of_limits = q0;
  out_of_limits[2] = 2.0;
  EXPECT_THROW(ik.solve(good, out_of_limits, q), InputError);
  Eigen::VectorXd nan = q0;
  nan[0] = std::nan("");
  EXPECT_THROW(ik.solve(good, nan, q), InputError);
  Eigen::Isometry3d skew = good;
  skew.matrix()(0, 1) += 0.1;
  EXPECT_THROW(ik.solve(skew, q0, q), InputError);
  Eigen::Isometry3d mirrored = good;
  mirrored.matrix().col(0) *= -1;
  EXPECT_THROW(ik.solve(mirrored, q0, q), InputError);
  Eigen::Isometry3d nan_pose = good;
  nan_pose.matrix()(1, 3) = std::nan("");
  EXPECT_THROW(ik.solve(nan_pose, q0, q), InputError);
  Vector6d neg = Vector6d::Zero();
  neg[3] = -1;
  EXPECT_THROW(ik.solve(good, q0, neg, q), InputError);
  for (double t : {0.0, -1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    TracIKOptions o;
    o.timeout = t;
    EXPECT_THROW(TracIK(model, o), InputError);
    o = TracIKOptions{};
    o.epsilon = t;
    EXPECT_THROW(TracIK(model, o), InputError);
  }
  EXPECT_THROW(solve_type_from_string("Fastest"), InputError);
  EXPECT_EQ(solve_type_from_string("Manip2"), SolveType::Manip2);
  EXPECT_THROW(TracIK(std::shared_ptr<const ChainModel>()), InputError);
  std::vector<Eigen::Isometry3d, Eigen::aligned_allocator<Eigen::Isometry3d>> targets(2, good);
  Eigen::MatrixXd qs = Eigen::MatrixXd::Zero(7, 3), qo;
  std::vector<bool> ok;
  EXPECT_THROW(ik.solve_many(targets, qs, qo, ok), InputError);
  EXPECT_THROW(kdl_nr_jl_ik(*model, skew, q0, q), InputError);
  EXPECT_THROW(kdl_nr_jl_ik(*model, good, q0, q, 0.0), InputError);
}

TEST(KdlNrJl, ConvergesFromNearbyAndRespectsLimits) {
  const auto model = head7();
  std::mt19937 rng(10);
  int solved = 0;
  for (int k = 0; k < 20; ++k) {
    const Eigen::VectorXd qt = random_q(*model, rng);
    const Eigen::Isometry3d target = forward_kinematics(*model, qt);
    Eigen::VectorXd q0 = qt;
    for (int i = 0; i < q0.size(); ++i) q0[i] = std::clamp(q0[i] + 0.02, model->lower()[i], model->upper()[i]);
    Eigen::VectorXd q;
    if (!kdl_nr_jl_ik(*model, target, q0, q, 0.01, 1e-5)) continue;
    ++solved;
    for (int i = 0; i < q.size(); ++i) {
      EXPECT_GE(q[i], model->lower()[i] - 1e-12);
      EXPECT_LE(q[i], model->upper()[i] + 1e-12);
    }
    // KDL's own test is per component of the base-frame twist: within sqrt(3) eps in norm.
    EXPECT_LE((forward_kinematics(*model, q).translation() - target.translation()).norm(), 2e-5);
  }
  EXPECT_GE(solved, 15);
}
