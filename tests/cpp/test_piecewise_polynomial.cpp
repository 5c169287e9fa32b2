// The core's piecewise polynomial (piecewise_polynomial.hpp) against Horner's rule on each interval, its
// extrapolation, one thread against two (the same numbers), and bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "snakehead/core_threads.hpp"
#include "snakehead/model.hpp"
#include "snakehead/piecewise_polynomial.hpp"

using namespace snakehead;

namespace {

// The polynomial of interval j, column l at x by Horner's rule (another order of operations: equal to round-off).
double horner(const std::vector<double>& c, long k, long m, long n, const std::vector<double>& breaks, long j, long l,
              double x) {
  double v = 0.0;
  for (long i = 0; i < k; ++i) v = v * (x - breaks[j]) + c[(i * m + j) * n + l];
  return v;
}

}  // namespace

TEST(PiecewisePolynomial, MatchesHornerInEachIntervalAndExtrapolates) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), step(0.1, 1.0);
  const long k = 6, m = 7, n = 3;
  std::vector<double> c(k * m * n), breaks(m + 1);
  for (double& v : c) v = unit(rng);
  breaks[0] = -1.0;
  for (long j = 1; j <= m; ++j) breaks[j] = breaks[j - 1] + step(rng);
  // inside each interval, on each break (its own interval, the last break the last interval's end), and outside
  std::vector<double> points;
  std::vector<long> interval;
  for (long j = 0; j < m; ++j) {
    points.push_back(breaks[j] + 0.3 * (breaks[j + 1] - breaks[j]));
    interval.push_back(j);
    points.push_back(breaks[j]);
    interval.push_back(j);
  }
  points.insert(points.end(), {breaks[m], breaks[0] - 0.5, breaks[m] + 0.5});
  interval.insert(interval.end(), {m - 1, 0, m - 1});
  const long N = static_cast<long>(points.size());
  std::vector<double> out(N * n);
  evaluate_piecewise_polynomial(c.data(), k, m, n, breaks.data(), points.data(), N, out.data());
  for (long p = 0; p < N; ++p)
    for (long l = 0; l < n; ++l)
      EXPECT_NEAR(out[p * n + l], horner(c, k, m, n, breaks, interval[p], l, points[p]), 1e-12) << "point " << p;
}

TEST(PiecewisePolynomial, ThreadsGiveTheSameNumbers) {
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const long k = 6, m = 50, n = 16, N = 100000;  // enough points for two threads
  std::vector<double> c(k * m * n), breaks(m + 1), points(N), one(N * n), two(N * n);
  for (double& v : c) v = unit(rng) - 0.5;
  for (long j = 0; j <= m; ++j) breaks[j] = static_cast<double>(j) + 0.5 * unit(rng);
  for (double& x : points) x = -1.0 + (m + 2.0) * unit(rng);
  const int threads = core_threads();
  set_core_threads(1);
  evaluate_piecewise_polynomial(c.data(), k, m, n, breaks.data(), points.data(), N, one.data());
  set_core_threads(2);
  evaluate_piecewise_polynomial(c.data(), k, m, n, breaks.data(), points.data(), N, two.data());
  set_core_threads(0);
  EXPECT_EQ(core_threads(), threads);
  EXPECT_EQ(one, two);
}

TEST(PiecewisePolynomial, BadInputThrows) {
  std::vector<double> c(6 * 2, 1.0), breaks{0.0, 1.0, 2.0}, points{0.5}, out(2);
  EXPECT_THROW(evaluate_piecewise_polynomial(c.data(), 0, 2, 1, breaks.data(), points.data(), 1, out.data()), InputError);
  EXPECT_THROW(evaluate_piecewise_polynomial(c.data(), 6, 0, 1, breaks.data(), points.data(), 1, out.data()), InputError);
  std::vector<double> flat{0.0, 1.0, 1.0}, holed{0.0, NAN, 2.0}, bad_point{INFINITY};
  EXPECT_THROW(evaluate_piecewise_polynomial(c.data(), 6, 2, 1, flat.data(), points.data(), 1, out.data()), InputError);
  EXPECT_THROW(evaluate_piecewise_polynomial(c.data(), 6, 2, 1, holed.data(), points.data(), 1, out.data()), InputError);
  EXPECT_THROW(evaluate_piecewise_polynomial(c.data(), 6, 2, 1, breaks.data(), bad_point.data(), 1, out.data()),
               InputError);
}
