// The ZMP check's time derivative (zmp_check.hpp) against a closed form.
#include <gtest/gtest.h>

#include <vector>

#include "snakehead/zmp_check.hpp"

namespace {

using namespace snakehead;

TEST(ZmpCheck, TimeDerivativeIsSecondOrderExact) {
  // numpy.gradient's second-order differences are exact on a quadratic, even on uneven steps
  const std::vector<double> t = {0.0, 0.1, 0.25, 0.3, 0.7};
  std::vector<double> x, dx(5);
  for (double s : t) x.push_back(3.0 * s * s - s + 2.0);
  time_derivative(t.data(), x.data(), 5, 1, dx.data());
  for (int k = 0; k < 5; ++k) EXPECT_NEAR(dx[k], 6.0 * t[k] - 1.0, 1e-12);
}

}  // namespace
