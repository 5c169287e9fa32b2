// The tracking fit's step (tracking_fit.hpp) against independent computations on a four-joint chain of boxes (yaw,
// pitch, yaw, pitch) lying on the ground and folded back on itself: the Jacobian of the stacked residual against
// central differences of the residual, and the step against the damped least-squares problem solved by QR,
// min |r + J dq|^2 + lambda^2 |dq|^2; fit() keeps the joints within their limits and rows 0 and S-1 as given.
#include <gtest/gtest.h>

#include <Eigen/QR>

#include <cmath>
#include <string>
#include <vector>

#include "snakehead/kinematics.hpp"
#include "snakehead/shape_set.hpp"
#include "snakehead/tracking_fit.hpp"
#include "four_link_chain.hpp"

namespace {

using namespace snakehead;

struct Fixture {
  ChainModel model = test::four_link_chain(0.09);
  ShapeSet shapes{test::four_link_boxes(model, 0.09)};
  Eigen::Matrix4d origin = Eigen::Matrix4d::Identity();
  TrackingSpec spec;
  TrackingSettings settings;

  Fixture() {
    origin(2, 3) = 0.0205;  // the boxes lie 0.5 mm above the ground when straight
    spec.lift = {1, 2, 3};
    for (int k = 2; k <= 4; ++k) spec.points.push_back(model.link_index("l" + std::to_string(k)));
    for (int k = 1; k <= 4; ++k) spec.lifted_links.push_back(model.link_index("l" + std::to_string(k)));
    spec.self_pairs = {{0, 2}, {0, 3}, {1, 3}};
    // the test's own settings (Python's TRACKING_* but for wider clearances, so that both terms are active here)
    settings.damping = 0.01;
    settings.iterations = 12;
    settings.step_tolerance = 1e-7;
    settings.clearance = 0.01;
    settings.ground_weight = 10.0;
    settings.continuity = 0.03;
    settings.self_clearance = 0.03;
    settings.self_step = 1e-6;
  }
};

TEST(TrackingFit, StepIsTheDampedLeastSquaresStepOfTheResidualsJacobian) {
  const Fixture fx;
  const TrackingFit fit(fx.model, fx.shapes, fx.origin, fx.spec, fx.settings);
  // l3 turned back beside l2 (yaw 2.6 rad) and slightly pitched: its box comes near l1's; every box near the ground
  Eigen::VectorXd q(4);
  q << 0.1, 0.05, 2.6, -0.1;
  const Eigen::VectorXd current = Eigen::Vector3d(0.02, 2.5, 0.0);
  const std::vector<double> target = {0.12, 0.01, 0.05, 0.15, 0.08, 0.06, 0.1, 0.12, 0.04};
  const TrackingStep s = fit.step(q, current, target.data());
  const long rows = s.residual.size();
  // the ground and self rows expected, counted independently: lifted boxes lower than the clearance, pairs closer
  Frames f;
  link_frames(fx.model, q, f);
  std::vector<double> frames(16 * f.size());
  for (std::size_t k = 0; k < f.size(); ++k)
    Eigen::Map<Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(frames.data() + 16 * k) = fx.origin * f[k].matrix();
  const long L = static_cast<long>(f.size());
  const std::vector<long> all = {0, 1, 2, 3}, pairs = {0, 2, 0, 3, 1, 3};
  std::vector<double> low(4), dist(3);
  lowest_z(frames.data(), 1, L, fx.shapes, all.data(), 4, low.data());
  pair_distances(frames.data(), 1, L, fx.shapes, frames.data(), 1, L, fx.shapes, pairs.data(), 3, 1.0, dist.data());
  long ground = 0, close = 0;
  for (double z : low) ground += z < fx.settings.clearance;
  for (double d : dist) close += d < fx.settings.self_clearance;
  ASSERT_GT(ground, 0);
  ASSERT_GT(close, 0);
  ASSERT_EQ(rows, 9 + ground + close + 3);  // the 3 points', the ground, self and continuity rows
  // the Jacobian against central differences of the residual (the same rows on both sides)
  const double h = 1e-5;
  for (int c = 0; c < 3; ++c) {
    Eigen::VectorXd qp = q, qm = q;
    qp[fx.spec.lift[c]] += h;
    qm[fx.spec.lift[c]] -= h;
    const TrackingStep p = fit.step(qp, current, target.data()), m = fit.step(qm, current, target.data());
    ASSERT_EQ(p.residual.size(), rows);
    ASSERT_EQ(m.residual.size(), rows);
    const Eigen::VectorXd fd = (p.residual - m.residual) / (2 * h);
    for (long r = 0; r < rows; ++r)
      EXPECT_NEAR(s.jacobian(r, c), fd[r], 1e-5 + 1e-4 * std::abs(fd[r])) << "row " << r << " joint " << c;
  }
  // the step: min |r + J dq|^2 + lambda^2 |dq|^2 as one least-squares problem, by QR
  Eigen::MatrixXd A(rows + 3, 3);
  Eigen::VectorXd b(rows + 3);
  A << s.jacobian, fx.settings.damping * Eigen::Matrix3d::Identity();
  b << -s.residual, Eigen::Vector3d::Zero();
  const Eigen::VectorXd dq = A.colPivHouseholderQr().solve(b);
  EXPECT_LT((dq - s.step).cwiseAbs().maxCoeff(), 1e-10);
}

TEST(TrackingFit, FitStaysWithinTheLimitsAndKeepsTheEnds) {
  Fixture fx;
  const TrackingFit fit(fx.model, fx.shapes, fx.origin, fx.spec, fx.settings);
  const long S = 5;
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> q(S, 4);
  for (long t = 0; t < S; ++t) q.row(t) << 0.0, 0.3 * t, -0.2 * t, 0.4 * t;
  const auto given = q;
  // targets far out of reach: the fit pushes every joint to a limit
  std::vector<double> targets(static_cast<std::size_t>(S * 3 * 3), 5.0);
  fit.fit(q.data(), S, targets.data());
  EXPECT_EQ(q.row(0), given.row(0));
  EXPECT_EQ(q.row(S - 1), given.row(S - 1));
  for (long t = 1; t + 1 < S; ++t) {
    EXPECT_EQ(q(t, 0), given(t, 0));  // not a lifted joint
    for (int j = 1; j < 4; ++j) {
      EXPECT_GE(q(t, j), -3.0);
      EXPECT_LE(q(t, j), 3.0);
    }
  }
  EXPECT_THROW(TrackingFit(fx.model, fx.shapes, fx.origin, TrackingSpec{{7}, {}, {}, {}}, fx.settings), InputError);
  fx.settings.self_step = 0.0;
  EXPECT_THROW(TrackingFit(fx.model, fx.shapes, fx.origin, fx.spec, fx.settings), InputError);
}

}  // namespace
