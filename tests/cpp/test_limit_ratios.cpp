// A timed motion's use of its limits (limit_ratios.hpp) against closed forms: a unit square support polygon and a
// ZMP placed by hand (Eqs. 39-40), joint ratios by hand, a sample whose ground would have to pull, bad sizes.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "snakehead/limit_ratios.hpp"
#include "snakehead/model.hpp"

using namespace snakehead;

TEST(LimitRatios, ClosedForms) {
  const long N = 2, n = 2, E = 4;
  const double Mg = 10.0, mu = 0.5;
  // the square [0, 1]^2: inward normals and offsets (inside where normal . p >= offset)
  const std::vector<double> square{1, 0, 0, 1, -1, 0, 0, -1};
  const std::vector<double> square_offset{0, 0, -1, -1};
  std::vector<double> normal, offset;
  for (long k = 0; k < N; ++k) {
    normal.insert(normal.end(), square.begin(), square.end());
    offset.insert(offset.end(), square_offset.begin(), square_offset.end());
  }
  const std::vector<double> qd{1.0, -3.0, 0.5, 0.5}, qdd{-4.0, 2.0, 0.0, 1.0}, tau{0.5, 1.0, -6.0, 0.0};
  const std::vector<double> velocity{2.0, 4.0}, acceleration{8.0, 1.0}, torque{1.0, 2.0};
  // sample 0: the CoM at (0.3, 0.4), L' = (1, 2, 0), P' = (3, 4, 10): ZMP x = (10*0.3 - 2) / 20 = 0.05,
  // y = (10*0.4 + 1) / 20 = 0.25, nearest edge x = 0: margin 0.05; friction 5 / (0.5 * 20) = 0.5.
  // sample 1: P'_z = -10, Mg + P'_z = 0: the ground would have to pull
  const std::vector<double> Pdot{3, 4, 10, 0, 0, -10}, Ldot{1, 2, 0, 0, 0, 0}, com{0.3, 0.4, 0.1, 0.5, 0.5, 0.1};
  const LimitRatios r = limit_ratios(N, n, E, qd.data(), qdd.data(), tau.data(), Pdot.data(), Ldot.data(), com.data(),
                                     normal.data(), offset.data(), velocity.data(), acceleration.data(), torque.data(),
                                     Mg, mu);
  EXPECT_DOUBLE_EQ(r.velocity[0], 0.75);
  EXPECT_DOUBLE_EQ(r.velocity[1], 0.25);
  EXPECT_DOUBLE_EQ(r.acceleration[0], 2.0);
  EXPECT_DOUBLE_EQ(r.acceleration[1], 1.0);
  EXPECT_DOUBLE_EQ(r.torque[0], 0.5);
  EXPECT_DOUBLE_EQ(r.torque[1], 6.0);
  EXPECT_NEAR(r.zmp_margin[0], 0.05, 1e-15);
  EXPECT_NEAR(r.friction[0], 0.5, 1e-15);
  EXPECT_EQ(r.zmp_margin[1], -std::numeric_limits<double>::infinity());
  EXPECT_EQ(r.friction[1], std::numeric_limits<double>::infinity());
  const LimitRatios none = limit_ratios(0, n, E, nullptr, nullptr, nullptr, nullptr, nullptr, nullptr, nullptr,
                                        nullptr, velocity.data(), acceleration.data(), torque.data(), Mg, mu);
  EXPECT_TRUE(none.velocity.empty());
  EXPECT_THROW(limit_ratios(N, 0, E, qd.data(), qdd.data(), tau.data(), Pdot.data(), Ldot.data(), com.data(),
                            normal.data(), offset.data(), velocity.data(), acceleration.data(), torque.data(), Mg, mu),
               InputError);
  EXPECT_THROW(limit_ratios(N, n, 0, qd.data(), qdd.data(), tau.data(), Pdot.data(), Ldot.data(), com.data(),
                            normal.data(), offset.data(), velocity.data(), acceleration.data(), torque.data(), Mg, mu),
               InputError);
}

TEST(LimitRatios, OnASlopeTheGroundPushesAgainstTheWeightAlongIt) {
  // one sample, the weight's part along the ground M g_xy = (-6, 0) N: the contact force along the ground is
  // dP_xy/dt - M g_xy = (3 + 6, 4) and the friction used |(9, 4)| / (mu (Mg + dP_z/dt)) = sqrt(97) / 10
  const long N = 1, n = 1, E = 1;
  const std::vector<double> normal{1, 0}, offset{0}, qd{0}, qdd{0}, tau{0}, limit{1};
  const std::vector<double> Pdot{3, 4, 10}, Ldot{0, 0, 0}, com{0.3, 0.4, 0.1};
  const LimitRatios r = limit_ratios(N, n, E, qd.data(), qdd.data(), tau.data(), Pdot.data(), Ldot.data(), com.data(),
                                     normal.data(), offset.data(), limit.data(), limit.data(), limit.data(), 10.0, 0.5,
                                     -6.0, 0.0);
  EXPECT_NEAR(r.friction[0], std::sqrt(97.0) / 10.0, 1e-15);
  const LimitRatios flat = limit_ratios(N, n, E, qd.data(), qdd.data(), tau.data(), Pdot.data(), Ldot.data(),
                                        com.data(), normal.data(), offset.data(), limit.data(), limit.data(),
                                        limit.data(), 10.0, 0.5);
  EXPECT_NEAR(flat.friction[0], 0.5, 1e-15);
}
