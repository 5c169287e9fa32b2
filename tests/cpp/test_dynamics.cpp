// Newton-Euler of the core against the closed form of a pendulum: a point mass on a massless arm about z.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "snakehead/core_threads.hpp"
#include "snakehead/dynamics.hpp"
#include "snakehead/model.hpp"

namespace {

snakehead::RigidBodyChain pendulum(double mass, double arm) {
  snakehead::RigidBodyChain chain;
  chain.joint_child = {1};
  chain.axis = {Eigen::Vector3d::UnitZ()};
  chain.mass = {0.0, mass};
  chain.com = {Eigen::Vector3d::Zero(), Eigen::Vector3d(arm, 0.0, 0.0)};
  chain.inertia = {Eigen::Matrix3d::Zero(), Eigen::Matrix3d::Zero()};
  return chain;
}

// Frames of the root (identity) and of the link turned by q about z, row-major 4x4 each.
std::vector<double> frames(double q) {
  std::vector<double> f(32, 0.0);
  for (int i = 0; i < 4; ++i) f[i * 5] = 1.0;
  const double c = std::cos(q), s = std::sin(q);
  const double link[16] = {c, -s, 0, 0, s, c, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  for (int i = 0; i < 16; ++i) f[16 + i] = link[i];
  return f;
}

TEST(NewtonEuler, PendulumMatchesItsClosedForm) {
  const double m = 0.7, r = 0.3, g = 9.81;
  const auto chain = pendulum(m, r);
  for (double q : {0.0, 0.4, 2.0}) {
    const std::vector<double> f = frames(q);
    const double qd = 1.3, qdd = -0.8;
    double tau = 0.0, force[3], moment[3];
    snakehead::newton_euler(chain, f.data(), &qd, &qdd, nullptr, Eigen::Vector3d(0.0, -g, 0.0), 1, 2, &tau, force,
                            moment);
    EXPECT_NEAR(tau, m * r * r * qdd + m * g * r * std::cos(q), 1e-12);
    // the inertial force is m times the mass's acceleration: tangential r qdd, centripetal r qd^2
    const Eigen::Vector3d radial(std::cos(q), std::sin(q), 0.0), tangent(-std::sin(q), std::cos(q), 0.0);
    const Eigen::Vector3d expected = m * (r * qdd * tangent - r * qd * qd * radial);
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(force[i], expected[i], 1e-12);
    EXPECT_NEAR(moment[2], m * r * r * qdd, 1e-12);  // the angular momentum's rate about the origin
    // resting on the ground (lifted share 0) the joint carries no weight, only the inertia
    const double share[2] = {0.0, 0.0};
    snakehead::newton_euler(chain, f.data(), &qd, &qdd, share, Eigen::Vector3d(0.0, -g, 0.0), 1, 2, &tau, force,
                            moment);
    EXPECT_NEAR(tau, m * r * r * qdd, 1e-12);
  }
}

TEST(Momenta, PendulumMatchesItsClosedForm) {
  const double m = 0.7, r = 0.3, q = 0.9, qd = -1.7;
  const auto chain = pendulum(m, r);
  const std::vector<double> f = frames(q);
  double P[3], L[3], c[3];
  snakehead::momenta(chain, f.data(), &qd, 1, 2, P, L, c);
  EXPECT_NEAR(P[0], -m * r * qd * std::sin(q), 1e-14);
  EXPECT_NEAR(P[1], m * r * qd * std::cos(q), 1e-14);
  EXPECT_NEAR(P[2], 0.0, 1e-14);
  EXPECT_NEAR(L[2], m * r * r * qd, 1e-14);
  EXPECT_NEAR(c[0], r * std::cos(q), 1e-14);
  EXPECT_NEAR(c[1], r * std::sin(q), 1e-14);
}

TEST(NewtonEuler, InconsistentChainsAreRejected) {
  auto chain = pendulum(1.0, 0.1);
  chain.joint_child = {0};  // the root link cannot be a joint's child
  const std::vector<double> f = frames(0.0);
  const double qd = 0.0, qdd = 0.0;
  double tau, force[3], moment[3];
  EXPECT_THROW(snakehead::newton_euler(chain, f.data(), &qd, &qdd, nullptr, Eigen::Vector3d::Zero(), 1, 2, &tau,
                                       force, moment),
               snakehead::InputError);
  chain = pendulum(1.0, 0.1);
  chain.mass.push_back(1.0);  // one more mass than coms
  EXPECT_THROW(snakehead::newton_euler(chain, f.data(), &qd, &qdd, nullptr, Eigen::Vector3d::Zero(), 1, 2, &tau,
                                       force, moment),
               snakehead::InputError);
}

}  // namespace

namespace {

// newton_euler_along over T random samples of the sample robot's whole chain on `threads` threads: tau, force,
// moment and com, one after the other.
std::vector<double> along(const snakehead::ChainModel& model, long T, int threads) {
  const snakehead::RigidBodyChain chain = snakehead::chain_dynamics(model);
  const long n = model.n_joints();
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<double> q(static_cast<std::size_t>(T * n)), qd(q.size()), qdd(q.size());
  for (std::size_t i = 0; i < q.size(); ++i) q[i] = u(rng), qd[i] = u(rng), qdd[i] = u(rng);
  std::vector<double> out(static_cast<std::size_t>(T * (n + 9)));
  snakehead::set_core_threads(threads);
  snakehead::newton_euler_along(model, Eigen::Matrix4d::Identity(), chain, nullptr, q.data(), qd.data(), qdd.data(),
                                Eigen::Vector3d(0.0, 0.0, -9.81), T, out.data(), out.data() + T * n,
                                out.data() + T * (n + 3), out.data() + T * (n + 6));
  snakehead::set_core_threads(0);
  return out;
}

}  // namespace

TEST(NewtonEuler, ThreadsGiveTheSerialResultBitForBit) {
  const auto model = snakehead::ChainModel::from_urdf(std::string(SNAKEHEAD_URDF_DIR) + "/snake16.urdf", "link_0",
                                                      "head_tip");
  const std::vector<double> serial = along(model, 1001, 1);
  EXPECT_EQ(along(model, 1001, 2), serial);
  EXPECT_EQ(along(model, 1001, 7), serial);
}
