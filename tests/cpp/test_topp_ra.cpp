// TOPP-RA (include/snakehead/topp_ra.hpp): the 2-D LP against brute force over the vertices of random LPs, and
// the passes against the closed-form bang-bang profile of a velocity- and acceleration-limited straight path.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <thread>
#include <vector>

#include "snakehead/model.hpp"
#include "snakehead/topp_ra.hpp"

namespace {

using snakehead::HalfPlane;
using snakehead::Lp2dSolution;
using snakehead::RowMatrixX2d;
using snakehead::RowMatrixXd;
using snakehead::ToppRaStatus;

struct BruteForce {
  bool feasible = false;
  double best = -std::numeric_limits<double>::infinity();
};

// max v . p over the vertices of {rows} and the box: every intersection of two of the lines (rows and box sides)
// that keeps all constraints (to 1e-9). A nonempty polygon inside a box has a vertex, and a linear objective is
// largest at one.
BruteForce brute_force(double vu, double vx, const std::vector<HalfPlane>& rows, const double lo[2],
                       const double hi[2]) {
  std::vector<HalfPlane> all = rows;
  all.push_back({-1, 0, -lo[0]});
  all.push_back({1, 0, hi[0]});
  all.push_back({0, -1, -lo[1]});
  all.push_back({0, 1, hi[1]});
  BruteForce out;
  for (std::size_t i = 0; i < all.size(); ++i)
    for (std::size_t j = i + 1; j < all.size(); ++j) {
      const double det = all[i].a * all[j].b - all[i].b * all[j].a;
      if (std::abs(det) < 1e-12) continue;
      const double u = (all[i].c * all[j].b - all[i].b * all[j].c) / det;
      const double x = (all[i].a * all[j].c - all[i].c * all[j].a) / det;
      bool ok = true;
      for (const HalfPlane& h : all) ok = ok && h.a * u + h.b * x <= h.c + 1e-9;
      if (!ok) continue;
      out.feasible = true;
      out.best = std::max(out.best, vu * u + vx * x);
    }
  return out;
}

TEST(Lp2d, MatchesBruteForceOnRandomLps) {
  std::mt19937 rng(7);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> side(0.5, 5.0), exponent(-6.0, 2.0);
  int feasible = 0, infeasible = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    const int m = trial % 25;
    std::vector<HalfPlane> rows(m);
    for (HalfPlane& h : rows) h = {normal(rng), normal(rng), normal(rng) + (trial % 2 ? 2.0 : 0.0)};
    // rows of very different scales, some nearly parallel to the u axis (as TOPP-RA's are: u spans +-1e8); a
    // wide box in u
    for (HalfPlane& h : rows) {
      const double scale = trial % 4 == 3 ? std::pow(10.0, exponent(rng)) : 1.0;
      h = {h.a * scale * (trial % 8 == 7 ? 1e-4 : 1.0), h.b * scale, h.c * scale};
    }
    std::vector<HalfPlane> unit(m);
    std::transform(rows.begin(), rows.end(), unit.begin(), snakehead::normalized);
    const double u_side = trial % 8 == 7 ? 1e6 : 1.0;
    const double lo[2] = {-u_side * side(rng), -side(rng)}, hi[2] = {u_side * side(rng), side(rng)};
    const double vu = normal(rng), vx = normal(rng);
    std::vector<int> order(m);
    for (int k = 0; k < m; ++k) order[k] = m - 1 - k;  // any order gives the optimum
    const Lp2dSolution s = snakehead::solve_lp2d(vu, vx, unit.data(), m, lo, hi, trial % 3 ? nullptr : order.data());
    const BruteForce b = brute_force(vu, vx, unit, lo, hi);
    ASSERT_EQ(s.feasible, b.feasible) << "trial " << trial;
    if (!s.feasible) {
      ++infeasible;
      continue;
    }
    ++feasible;
    EXPECT_NEAR(vu * s.u + vx * s.x, b.best, 1e-7 * (1.0 + std::abs(b.best))) << "trial " << trial;
    for (const HalfPlane& h : rows) EXPECT_LE(h.a * s.u + h.b * s.x, h.c + 1e-8) << "trial " << trial;
    EXPECT_GE(s.u, lo[0] - 1e-12);
    EXPECT_LE(s.u, hi[0] + 1e-12);
    EXPECT_GE(s.x, lo[1] - 1e-12);
    EXPECT_LE(s.x, hi[1] + 1e-12);
  }
  EXPECT_GT(feasible, 1000);
  EXPECT_GT(infeasible, 100);
}

TEST(Lp2d, EmptyBoxAndBrokenZeroRowAreInfeasible) {
  const double lo[2] = {0, 0}, hi[2] = {1, 1}, empty_hi[2] = {-1, 1};
  EXPECT_FALSE(snakehead::solve_lp2d(1, 1, nullptr, 0, lo, empty_hi).feasible);
  const HalfPlane zero{0, 0, -1};  // 0 <= -1
  EXPECT_FALSE(snakehead::solve_lp2d(1, 1, &zero, 1, lo, hi).feasible);
  const HalfPlane kept{0, 0, 1};  // 0 <= 1
  const Lp2dSolution s = snakehead::solve_lp2d(1, 1, &kept, 1, lo, hi);
  EXPECT_TRUE(s.feasible);
  EXPECT_EQ(s.u, 1.0);
  EXPECT_EQ(s.x, 1.0);
}

// A row with small coefficients whose line passes far from the origin, met first at the box's corner u = 1e8 (the
// u bounds are +-1e8 in TOPP-RA): the optimum walks ~4e7 along its line back into the box. (toppra's bound of
// +-1e10 on the unnormalised line parameter, ~2e5 in length here, made this LP infeasible: a planner's lift failed.)
TEST(Lp2d, RowWithSmallCoefficientsFarAlongItsLine) {
  const double delta = 0.018;
  const HalfPlane rows[3] = {snakehead::normalized({1.81e-7, -1.73e-5, 7.96}),
                             snakehead::normalized({2 * delta, 1, 0}), snakehead::normalized({-2 * delta, -1, 0})};
  const double lo[2] = {-1e8, 0}, hi[2] = {1e8, 114};
  const Lp2dSolution s = snakehead::solve_lp2d(1e-9, -1, rows, 3, lo, hi);  // min x (toppra's objective for K_lo)
  ASSERT_TRUE(s.feasible);
  EXPECT_NEAR(s.x, 0.0, 1e-9);
  EXPECT_NEAR(s.u, 0.0, 1e-6);
  const int first_row_first[3] = {0, 1, 2};
  EXPECT_TRUE(snakehead::solve_lp2d(-1e-9, 1, rows, 3, lo, hi, first_row_first).feasible);  // max x
}

// A straight path of length L (q(s) = s, one joint) with |q'| <= v and |q''| <= a: u in [-a, a] (rows u <= a,
// -u <= a at both ends of each stage), x <= v^2. The fastest motion from rest to rest is bang-bang:
// x(s) = min(2 a s, v^2, 2 a (L - s)), and each stage's constant u gives exactly that at the gridpoints.
struct StraightPath {
  double L = 1.2, v = 0.8, a = 1.6;  // the profile's corners v^2 / (2 a) = 0.2 from either end: gridpoints
  int N = 60;
  Eigen::VectorXd grid;
  RowMatrixXd A, B, C;
  RowMatrixX2d u_bounds, x_bounds;

  explicit StraightPath(int rows_per_stage = 4) {
    grid = Eigen::VectorXd::LinSpaced(N + 1, 0.0, L);
    A = RowMatrixXd::Zero(N, rows_per_stage);
    B = RowMatrixXd::Zero(N, rows_per_stage);
    C = RowMatrixXd::Constant(N, rows_per_stage, a);
    for (int k = 0; k < rows_per_stage; ++k) A.col(k).setConstant(k % 2 ? -1.0 : 1.0);
    u_bounds = RowMatrixX2d::Constant(N, 2, std::numeric_limits<double>::infinity());
    u_bounds.col(0).setConstant(-std::numeric_limits<double>::infinity());
    x_bounds = RowMatrixX2d::Zero(N + 1, 2);
    x_bounds.col(1).setConstant(v * v);
  }
  double x_exact(double s) const { return std::min({2 * a * s, v * v, 2 * a * (L - s)}); }
  snakehead::ToppRaResult solve(double x_start = 0.0) const {
    return snakehead::topp_ra(grid, A, B, C, u_bounds, x_bounds, x_start, 0.0);
  }
};

TEST(ToppRa, BangBangProfileOfAStraightPath) {
  const StraightPath p;
  const snakehead::ToppRaResult r = p.solve();
  ASSERT_EQ(r.status, ToppRaStatus::kFeasible);
  EXPECT_EQ(r.failed_at, -1);
  for (int i = 0; i <= p.N; ++i) {
    const double s = p.grid(i);
    // K_i: from 0 up to the speed from which braking at a still reaches rest at L (and at most v^2)
    EXPECT_NEAR(r.K(i, 0), 0.0, 1e-12) << i;
    EXPECT_NEAR(r.K(i, 1), std::min(p.v * p.v, 2 * p.a * (p.L - s)), 1e-9) << i;
    // the profile: within the forward pass's shrink (1e-8 per stage) of the bang-bang one
    EXPECT_NEAR(r.x[i], p.x_exact(s), 1e-6) << i;
    EXPECT_LE(r.x[i], r.K(i, 1) + 1e-12);
  }
  for (int i = 0; i < p.N; ++i) EXPECT_LE(std::abs(r.u[i]), p.a * (1 + 1e-9)) << i;
  // the duration: sum of delta / mean speed over the stages, against L / v + v / a (accelerate, cruise, brake)
  double T = 0;
  for (int i = 0; i < p.N; ++i) T += (p.grid(i + 1) - p.grid(i)) / (0.5 * (std::sqrt(r.x[i]) + std::sqrt(r.x[i + 1])));
  EXPECT_NEAR(T, p.L / p.v + p.v / p.a, 1e-6);
}

TEST(ToppRa, InfeasibleAtTheRightPlace) {
  StraightPath p;
  // at gridpoint 55 the path must run faster than braking to rest at L allows: K_40 is empty
  const int j = 55;
  p.x_bounds(j, 0) = 0.5 * (p.v * p.v + 2 * p.a * (p.L - p.grid(j)));
  ASSERT_GT(p.x_bounds(j, 0), 2 * p.a * (p.L - p.grid(j)));
  const snakehead::ToppRaResult r = p.solve();
  EXPECT_EQ(r.status, ToppRaStatus::kUncontrollable);
  EXPECT_EQ(r.failed_at, j);
  for (int i = 0; i <= j; ++i) EXPECT_TRUE(std::isnan(r.K(i, 0)) && std::isnan(r.K(i, 1))) << i;
  for (int i = j + 1; i <= p.N; ++i) EXPECT_FALSE(std::isnan(r.K(i, 1))) << i;
  EXPECT_TRUE(std::isnan(r.x[0]));
  // a start faster than the path allows
  const snakehead::ToppRaResult fast = StraightPath().solve(2.0);
  EXPECT_EQ(fast.status, ToppRaStatus::kStartOutside);
  EXPECT_EQ(fast.failed_at, 0);
  // a row no state keeps at stage 10 (0 u + 0 x <= -1)
  StraightPath q;
  q.C(10, 3) = -1.0;
  q.A(10, 3) = 0.0;
  const snakehead::ToppRaResult broken = q.solve();
  EXPECT_EQ(broken.status, ToppRaStatus::kUncontrollable);
  EXPECT_EQ(broken.failed_at, 10);
}

TEST(ToppRa, SameResultFromManyThreads) {
  const StraightPath p(12);
  const snakehead::ToppRaResult one = p.solve();
  std::vector<snakehead::ToppRaResult> results(4);
  std::vector<std::thread> threads;
  for (auto& r : results) threads.emplace_back([&p, &r] { r = p.solve(); });
  for (auto& t : threads) t.join();
  for (const auto& r : results) {
    EXPECT_EQ(r.x, one.x);
    EXPECT_TRUE(r.K.isApprox(one.K));
  }
}

// topp_ra_canonical discretizes the gridpoints' rows itself: the same result, to the bit, as topp_ra over the stage
// matrices of the interpolation discretization (A = [P_i, P_{i+1} + 2 delta_i Q_{i+1}], B = [Q_i, Q_{i+1}],
// C = [R_i, R_{i+1}]) on random rows, feasible and not, and on the bang-bang path; malformed rows throw.
TEST(ToppRa, CanonicalRowsGiveTheStageMatricesResult) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> coefficient(-2.0, 2.0), room(0.2, 3.0), step(0.005, 0.05);
  int feasible = 0, infeasible = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const int N = 20 + trial, m = 1 + trial % 9;
    Eigen::VectorXd grid(N + 1);
    grid(0) = 0.0;
    for (int i = 0; i < N; ++i) grid(i + 1) = grid(i) + step(rng);
    RowMatrixXd P(N + 1, m), Q(N + 1, m), R(N + 1, m);
    for (int i = 0; i <= N; ++i)
      for (int k = 0; k < m; ++k) {
        P(i, k) = coefficient(rng);
        Q(i, k) = coefficient(rng);
        R(i, k) = trial % 4 == 3 && i == N / 2 && k == 0 ? -room(rng) : room(rng);  // some paths infeasible
      }
    Eigen::VectorXd x_max = Eigen::VectorXd::Constant(N + 1, 4.0);
    RowMatrixXd A(N, 2 * m), B(N, 2 * m), C(N, 2 * m);
    for (int i = 0; i < N; ++i) {
      const double delta = grid(i + 1) - grid(i);
      A.row(i) << P.row(i), P.row(i + 1) + 2.0 * delta * Q.row(i + 1);
      B.row(i) << Q.row(i), Q.row(i + 1);
      C.row(i) << R.row(i), R.row(i + 1);
    }
    RowMatrixX2d u_bounds(N, 2), x_bounds(N + 1, 2);
    u_bounds.col(0).setConstant(-std::numeric_limits<double>::infinity());
    u_bounds.col(1).setConstant(std::numeric_limits<double>::infinity());
    x_bounds.col(0).setZero();
    x_bounds.col(1) = x_max;
    const snakehead::ToppRaResult ref = snakehead::topp_ra(grid, A, B, C, u_bounds, x_bounds, 0.0, 0.0);
    const snakehead::ToppRaResult ours = snakehead::topp_ra_canonical(grid, P, Q, R, x_max, 0.0, 0.0);
    ASSERT_EQ(ours.status, ref.status) << trial;
    EXPECT_EQ(ours.failed_at, ref.failed_at) << trial;
    EXPECT_EQ(ours.lp_count, ref.lp_count) << trial;
    for (int i = 0; i <= N; ++i) {
      EXPECT_TRUE(ours.x[i] == ref.x[i] || (std::isnan(ours.x[i]) && std::isnan(ref.x[i]))) << trial << " " << i;
      for (int c = 0; c < 2; ++c)
        EXPECT_TRUE(ours.K(i, c) == ref.K(i, c) || (std::isnan(ours.K(i, c)) && std::isnan(ref.K(i, c))));
    }
    (ref.status == ToppRaStatus::kFeasible ? feasible : infeasible) += 1;
  }
  EXPECT_GE(feasible, 5);
  EXPECT_GE(infeasible, 5);
  using snakehead::InputError;
  const Eigen::VectorXd grid = Eigen::VectorXd::LinSpaced(4, 0.0, 1.0), x_max = Eigen::VectorXd::Ones(4);
  const RowMatrixXd P = RowMatrixXd::Ones(4, 2);
  RowMatrixXd bad = P;
  bad(1, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(snakehead::topp_ra_canonical(grid, bad, P, P, x_max, 0, 0), InputError);
  EXPECT_THROW(snakehead::topp_ra_canonical(grid, P, P.topRows(3), P, x_max, 0, 0), InputError);
  EXPECT_THROW(snakehead::topp_ra_canonical(grid, P, P, P, x_max.head(3), 0, 0), InputError);
  EXPECT_THROW(snakehead::topp_ra_canonical(grid.reverse(), P, P, P, x_max, 0, 0), InputError);
}

TEST(ToppRa, MalformedInputThrows) {
  const StraightPath p;
  using snakehead::InputError;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  Eigen::VectorXd grid = p.grid;
  grid(5) = grid(4);
  EXPECT_THROW(snakehead::topp_ra(grid, p.A, p.B, p.C, p.u_bounds, p.x_bounds, 0, 0), InputError);
  EXPECT_THROW(snakehead::topp_ra(p.grid.head(1), p.A.topRows(0), p.B.topRows(0), p.C.topRows(0),
                                  p.u_bounds.topRows(0), p.x_bounds.topRows(1), 0, 0),
               InputError);
  RowMatrixXd A = p.A;
  A(3, 1) = nan;
  EXPECT_THROW(snakehead::topp_ra(p.grid, A, p.B, p.C, p.u_bounds, p.x_bounds, 0, 0), InputError);
  EXPECT_THROW(snakehead::topp_ra(p.grid, p.A, p.B.leftCols(3), p.C, p.u_bounds, p.x_bounds, 0, 0), InputError);
  EXPECT_THROW(snakehead::topp_ra(p.grid, p.A, p.B, p.C, p.u_bounds, p.x_bounds.topRows(p.N), 0, 0), InputError);
  RowMatrixX2d xb = p.x_bounds;
  xb(7, 1) = nan;
  EXPECT_THROW(snakehead::topp_ra(p.grid, p.A, p.B, p.C, p.u_bounds, xb, 0, 0), InputError);
  EXPECT_THROW(snakehead::topp_ra(p.grid, p.A, p.B, p.C, p.u_bounds, p.x_bounds, -1, 0), InputError);
  EXPECT_THROW(snakehead::topp_ra(p.grid, p.A, p.B, p.C, p.u_bounds, p.x_bounds, 0, nan), InputError);
}

}  // namespace
