// The path check's motion bound (path_check.hpp) against brute force: along random straight joint segments of a
// four-joint chain (yaw, pitch, yaw, pitch) of boxes, no corner of any box moves farther than its bound B_S and no
// box's lowest point changes by more than Z_S, at 200 points of the segment; a path proven clear is clear there.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "snakehead/kinematics.hpp"
#include "snakehead/path_check.hpp"
#include "four_link_chain.hpp"

namespace {

using namespace snakehead;

struct Fixture {
  ChainModel model = test::four_link_chain(0.1);
  std::vector<ConvexShape> shapes_of() const { return test::four_link_boxes(model, 0.1); }
};

// World corners (3 x 8) of shape s at configuration q.
Eigen::Matrix<double, 3, 8> corners(const ChainModel& model, const Eigen::Isometry3d& origin, const ConvexShape& s,
                                    const Eigen::VectorXd& q) {
  Frames f;
  link_frames(model, q, f);
  const Eigen::Isometry3d pose = origin * f[static_cast<std::size_t>(s.frame)] * s.origin;
  Eigen::Matrix<double, 3, 8> out;
  for (int c = 0; c < 8; ++c) {
    Eigen::Vector3d p;
    for (int d = 0; d < 3; ++d) p(d) = (c >> d & 1 ? 0.5 : -0.5) * s.size(d);
    out.col(c) = pose * p;
  }
  return out;
}

TEST(PathCheck, MotionBoundHoldsAlongRandomSegments) {
  const Fixture fx;
  const ShapeSet shapes(fx.shapes_of());
  Eigen::Isometry3d origin = Eigen::Isometry3d::Identity();
  origin.translation() = Eigen::Vector3d(0.2, -0.1, 0.03);
  PathCheckSpec spec;
  spec.ground_shapes = {0, 1, 2, 3};
  const PathChecker checker(fx.model, shapes, origin.matrix(), spec);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> angle(-1.5, 1.5), step(-0.4, 0.4);
  double worst = 0.0, worst_z = 0.0;
  for (int trial = 0; trial < 200; ++trial) {
    Eigen::VectorXd qa(4), qb(4);
    for (int j = 0; j < 4; ++j) {
      qa[j] = angle(rng);
      qb[j] = qa[j] + step(rng);
    }
    std::vector<double> B, Z;
    checker.motion_bounds(qa, qb, B, Z);
    for (int s = 0; s < 4; ++s) {
      const auto start = corners(fx.model, origin, shapes.shape(s), qa);
      for (int k = 1; k <= 200; ++k) {
        const auto now = corners(fx.model, origin, shapes.shape(s), qa + (k / 200.0) * (qb - qa));
        const double moved = (now - start).colwise().norm().maxCoeff();
        const double dz = std::abs(now.row(2).minCoeff() - start.row(2).minCoeff());
        EXPECT_LE(moved, B[s] + 1e-12) << "shape " << s << " trial " << trial;
        EXPECT_LE(dz, Z[s] + 1e-12) << "shape " << s << " trial " << trial;
        worst = std::max(worst, moved / B[s]);
        worst_z = std::max(worst_z, B[s] > 0 && Z[s] > 0 ? dz / Z[s] : 0.0);
      }
    }
  }
  EXPECT_GT(worst, 0.5);  // the bound is not vacuous: some corner moves more than half of it
}

TEST(PathCheck, YawAboutAVerticalAxisMovesNothingUpOrDown) {
  const Fixture fx;
  const ShapeSet shapes(fx.shapes_of());
  PathCheckSpec spec;
  const PathChecker checker(fx.model, shapes, Eigen::Matrix4d::Identity(), spec);
  Eigen::VectorXd qa = Eigen::VectorXd::Zero(4), qb = qa;
  qb[0] = 0.8;  // the first (vertical) yaw joint only: everything turns in the plane
  std::vector<double> B, Z;
  checker.motion_bounds(qa, qb, B, Z);
  for (int s = 0; s < 4; ++s) {
    EXPECT_GT(B[s], 0.0);
    EXPECT_EQ(Z[s], 0.0);
  }
}

// The chain 5 cm above the ground, its boxes' lowest points to stay >= 0.
Eigen::Isometry3d raised() {
  Eigen::Isometry3d origin = Eigen::Isometry3d::Identity();
  origin.translation().z() = 0.05;
  return origin;
}

PathChecker ground_checker(const Fixture& fx, const ShapeSet& shapes) {
  PathCheckSpec spec;
  spec.ground_shapes = {0, 1, 2, 3};
  spec.ground_floor = 0.0;
  return PathChecker(fx.model, shapes, raised().matrix(), spec);
}

TEST(PathCheck, ProvenClearPathIsClearAtFineSamples) {
  const Fixture fx;
  const ShapeSet shapes(fx.shapes_of());
  const Eigen::Isometry3d origin = raised();
  const PathChecker checker = ground_checker(fx, shapes);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> angle(-0.6, 0.6);
  int proven = 0;
  for (int trial = 0; trial < 100; ++trial) {
    std::vector<double> w(8);
    for (double& x : w) x = angle(rng);
    PathOptions o;
    o.stop_at_violation = false;
    const PathVerdict v = checker.check_path(w.data(), 2, o);
    if (!v.clear()) continue;
    ++proven;
    const Eigen::Map<const Eigen::VectorXd> qa(w.data(), 4), qb(w.data() + 4, 4);
    for (int k = 0; k <= 1000; ++k)
      for (int s = 0; s < 4; ++s)
        EXPECT_GE(corners(fx.model, origin, shapes.shape(s), qa + (k / 1000.0) * (qb - qa)).row(2).minCoeff(), -1e-12);
  }
  EXPECT_GT(proven, 10);
}

TEST(PathCheck, ProvenClearMotionIsClearBetweenItsSamples) {
  // a motion that swings back and forth (its joints' total variation well above their net change) sampled at 41
  // points and evaluated every 0.3 rad of travel: proven clear -> clear at 20 points of every straight step between
  // samples; and a motion proven clear at one first step is proven at the others
  const Fixture fx;
  const ShapeSet shapes(fx.shapes_of());
  const Eigen::Isometry3d origin = raised();
  const PathChecker checker = ground_checker(fx, shapes);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> angle(-0.5, 0.5), phase(0.0, 6.3);
  int proven = 0, failed = 0;
  long evaluated = 0;
  for (int trial = 0; trial < 60; ++trial) {
    Eigen::Vector4d a, b, p;
    for (int j = 0; j < 4; ++j) a[j] = angle(rng), b[j] = angle(rng), p[j] = phase(rng);
    std::vector<double> qs;
    for (int k = 0; k <= 40; ++k)
      for (int j = 0; j < 4; ++j) qs.push_back(a[j] + b[j] * std::sin(3.0 * k / 40.0 * 6.3 + p[j]));
    PathOptions o;
    o.first_step = 0.3;
    const MotionVerdict v = checker.check_motion(qs.data(), 41, o);
    if (!v.clear()) {
      ++failed;
      continue;
    }
    ++proven;
    evaluated += v.samples;
    for (int k = 0; k < 40; ++k) {
      const Eigen::Map<const Eigen::VectorXd> qa(qs.data() + 4 * k, 4), qb(qs.data() + 4 * (k + 1), 4);
      for (int f = 0; f < 20; ++f)
        for (int s = 0; s < 4; ++s)
          EXPECT_GE(corners(fx.model, origin, shapes.shape(s), qa + (f / 20.0) * (qb - qa)).row(2).minCoeff(), -1e-12)
              << "trial " << trial << " step " << k;
    }
    o.first_step = 2.0;
    EXPECT_TRUE(checker.check_motion(qs.data(), 41, o).clear());
  }
  EXPECT_GT(proven, 5);
  EXPECT_GT(failed, 5);
  EXPECT_LT(evaluated, 41 * proven);  // not every sample is evaluated
}

}  // namespace
