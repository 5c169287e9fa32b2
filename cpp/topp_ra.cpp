#include "snakehead/topp_ra.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <random>
#include <string>

#include "snakehead/limits.hpp"
#include "snakehead/model.hpp"

namespace snakehead {

namespace {

// toppra's constants (toppra 0.6: solverwrapper/cy_seidel_solverwrapper.pyx, constants.py and
// algorithm/reachabilitybased), kept so that both give the same sets and profiles.
constexpr double kTiny = 1e-10;        // a row is kept when broken by less; |coefficient| below: zero
constexpr double kSmall = 1e-8;        // a row parallel to the line of the optimum is broken by more: infeasible
constexpr double kVarLimit = 1e8;      // |u|, |x| at most this (unbounded sides are taken at it)
constexpr double kTieWeight = 1e-9;    // weight of u in the objective of K's LPs: among equal x, the least |u| side
constexpr double kStartTolerance = 1e-5;  // x_start may lie this far outside K_0
constexpr double kStepShrink = 1e-8;      // the forward pass lowers each x_{i+1} by this (or by kStepShrinkShare)
constexpr double kStepShrinkShare = 0.9999;
constexpr double kRetryShare = 0.999;  // a forward step with no u retries from x_i lowered by this share (or kStepShrink)
constexpr int kMaxRetries = 10;
// The seed of the rows' random order: fixed, so that a solve is reproducible (any seed gives the same optimum).
constexpr std::uint32_t kOrderSeed = 0x70bbau;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The best point on the line h (a u + b x = c) under the rows order[0..k) and the box: a 1-D LP in the line's
// parameter t, p(t) = p0 + t d with d a unit vector. False when infeasible (an empty interval, or a parallel row
// broken). (toppra's seidel solver takes d = (-b, a) unnormalised and bounds t by +-1e10: on the line of a row with
// small coefficients, e.g. 1e-7 u - 2e-5 x <= 8, that bound cuts off the box, and an LP that has a solution is
// reported infeasible. Here t is a length, and the box bounds it.)
bool optimum_on_line(const double v[2], const HalfPlane& h, const HalfPlane* rows, const int* order, int k,
                     const double lo[2], const double hi[2], double p[2], int* active) {
  const double nn = h.a * h.a + h.b * h.b;
  if (!(nn > 0.0)) return false;  // 0 u + 0 x <= c with c < 0: no point keeps it
  const double p0[2] = {h.a * h.c / nn, h.b * h.c / nn};  // the line's point nearest the origin
  const double norm = std::sqrt(nn);
  const double d[2] = {-h.b / norm, h.a / norm};
  constexpr double kInf = std::numeric_limits<double>::infinity();
  double t_lo = -kInf, t_hi = kInf;
  int id_lo = 0, id_hi = 0;
  auto clip = [&](double a, double b, double c, int id) {
    const double slope = a * d[0] + b * d[1];
    const double room = c - (a * p0[0] + b * p0[1]);
    if (slope > kTiny) {
      const double t = room / slope;
      if (t < t_hi) t_hi = t, id_hi = id;
    } else if (slope < -kTiny) {
      const double t = room / slope;
      if (t > t_lo) t_lo = t, id_lo = id;
    } else if (room < -kSmall) {
      return false;  // parallel to the line and broken all along it
    }
    return true;
  };
  for (int j = 0; j < k; ++j) {
    const int r = order ? order[j] : j;
    if (!clip(rows[r].a, rows[r].b, rows[r].c, r)) return false;
  }
  if (!clip(-1.0, 0.0, -lo[0], kULow) || !clip(1.0, 0.0, hi[0], kUHigh) || !clip(0.0, -1.0, -lo[1], kXLow) ||
      !clip(0.0, 1.0, hi[1], kXHigh))
    return false;
  if (t_lo > t_hi) return false;
  const bool up = v[0] * d[0] + v[1] * d[1] > kTiny;  // else (also when the objective is level along the line) down
  const double t = up ? t_hi : t_lo;
  if (!std::isfinite(t)) return false;  // unbounded along the line: cannot happen with a finite box (|d| = 1)
  p[0] = p0[0] + t * d[0];
  p[1] = p0[1] + t * d[1];
  *active = up ? id_hi : id_lo;
  return true;
}

// Row (a, b, c) with a unit normal as UnitRows scales it: multiplied by 1 / sqrt(a^2 + b^2) (as it is when that is
// 0), so that a row scaled here and one scaled there are the same to the bit.
HalfPlane unit_row(double a, double b, double c) {
  const double norm = std::sqrt(a * a + b * b);
  const double scale = norm > 0.0 ? 1.0 / norm : 1.0;
  return {a * scale, b * scale, c * scale};
}

// The stage rows with unit normals (a, b), all at once (rows 0 u + 0 x <= c as they are).
struct UnitRows {
  RowMatrixXd a, b, c;
  UnitRows(const Eigen::Ref<const RowMatrixXd>& A, const Eigen::Ref<const RowMatrixXd>& B,
           const Eigen::Ref<const RowMatrixXd>& C) {
    Eigen::ArrayXXd norm = (A.array().square() + B.array().square()).sqrt();
    if (!norm.allFinite())  // the squares overflowed (|a| or |b| > 1e154)
      for (Eigen::Index i = 0; i < norm.rows(); ++i)
        for (Eigen::Index k = 0; k < norm.cols(); ++k) norm(i, k) = std::hypot(A(i, k), B(i, k));
    const Eigen::ArrayXXd scale = (norm > 0.0).select(norm.inverse(), 1.0);
    a = (A.array() * scale).matrix();
    b = (B.array() * scale).matrix();
    c = (C.array() * scale).matrix();
  }
};

// Stage i's LP: the two rows that keep x + 2 delta u in [K_lo, K_hi] (rows 0 and 1), then its m rows.
void fill_stage(std::vector<HalfPlane>& rows, double delta, double K_lo, double K_hi, const UnitRows& stage,
                Eigen::Index i) {
  rows[0] = normalized({2.0 * delta, 1.0, K_hi});
  rows[1] = normalized({-2.0 * delta, -1.0, -K_lo});
  for (Eigen::Index k = 0; k < stage.a.cols(); ++k) rows[2 + k] = {stage.a(i, k), stage.b(i, k), stage.c(i, k)};
}

// The stage rows of topp_ra_canonical, made stage by stage where they are used (no N x 2m matrices: the two passes
// make each stage's rows once each, which costs less than writing and reading them back): stage i's rows are the
// gridpoint rows of i at (u, x), then those of i+1 at (u, x + 2 delta_i u), each scaled as UnitRows scales them (the
// interpolation discretization as retiming._topp.interpolated makes it, to the bit).
struct CanonicalStages {
  const Eigen::Ref<const Eigen::VectorXd>& grid;
  const Eigen::Ref<const RowMatrixXd>& P;
  const Eigen::Ref<const RowMatrixXd>& Q;
  const Eigen::Ref<const RowMatrixXd>& R;
  bool overflow = false;  // some row's squares overflow: every row is scaled by hypot instead, as UnitRows does

  Eigen::Index cols() const { return 2 * P.cols(); }

  HalfPlane scaled(double a, double b, double c) const {
    if (!overflow) return unit_row(a, b, c);
    const double norm = std::hypot(a, b);
    const double scale = norm > 0.0 ? 1.0 / norm : 1.0;
    return {a * scale, b * scale, c * scale};
  }

  void fill(std::vector<HalfPlane>& rows, double delta, double K_lo, double K_hi, Eigen::Index i) const {
    rows[0] = normalized({2.0 * delta, 1.0, K_hi});
    rows[1] = normalized({-2.0 * delta, -1.0, -K_lo});
    const Eigen::Index m = P.cols();
    const double twice = 2.0 * delta;
    HalfPlane* out = rows.data() + 2;
    for (Eigen::Index k = 0; k < m; ++k) out[k] = scaled(P(i, k), Q(i, k), R(i, k));
    for (Eigen::Index k = 0; k < m; ++k) out[m + k] = scaled(P(i + 1, k) + twice * Q(i + 1, k), Q(i + 1, k), R(i + 1, k));
  }
};

// UnitRows' view of topp_ra's stage matrices (rows copied from them).
struct MatrixStages {
  const UnitRows& stage;
  Eigen::Index cols() const { return stage.a.cols(); }
  void fill(std::vector<HalfPlane>& rows, double delta, double K_lo, double K_hi, Eigen::Index i) const {
    fill_stage(rows, delta, K_lo, K_hi, stage, i);
  }
};

// The box of stage i's LP: its own bounds, sides at most kVarLimit, and x >= 0 (x = s'^2).
void stage_box(const Eigen::Ref<const RowMatrixX2d>& u_bounds, const Eigen::Ref<const RowMatrixX2d>& x_bounds,
               Eigen::Index i, double lo[2], double hi[2]) {
  lo[0] = std::max(u_bounds(i, 0), -kVarLimit);
  hi[0] = std::min(u_bounds(i, 1), kVarLimit);
  lo[1] = std::max({x_bounds(i, 0), 0.0, -kVarLimit});
  hi[1] = std::min(x_bounds(i, 1), kVarLimit);
}

// The rows' order for one LP: the rows active at the last optimum of its kind first (toppra's warm start: the
// second, then the first), then the rest in the call's random order.
void warm_order(const std::vector<int>& shuffled, const int active[2], std::vector<int>& order) {
  const int n = static_cast<int>(shuffled.size());
  const bool warm = active[0] >= 0 && active[0] < n && active[1] >= 0 && active[1] < n && active[0] != active[1];
  if (!warm) {
    order = shuffled;
    return;
  }
  order.clear();
  order.push_back(active[1]);
  order.push_back(active[0]);
  for (int r : shuffled)
    if (r != active[0] && r != active[1]) order.push_back(r);
}

void validate(const Eigen::Ref<const Eigen::VectorXd>& grid, const Eigen::Ref<const RowMatrixXd>& A,
              const Eigen::Ref<const RowMatrixXd>& B, const Eigen::Ref<const RowMatrixXd>& C,
              const Eigen::Ref<const RowMatrixX2d>& u_bounds, const Eigen::Ref<const RowMatrixX2d>& x_bounds,
              double x_start, double x_end) {
  const Eigen::Index points = grid.size();
  if (points < 2) throw InputError("grid needs at least two gridpoints, got " + std::to_string(points));
  if (points - 1 > std::numeric_limits<int>::max() / 2 || A.cols() > std::numeric_limits<int>::max() / 2 - 2)
    throw InputError("grid or rows too large for TOPP-RA");
  const Eigen::Index N = points - 1;
  if (!grid.allFinite()) throw InputError("grid must be finite");
  for (Eigen::Index i = 0; i < N; ++i)
    if (!(grid(i + 1) > grid(i)))
      throw InputError("grid must be strictly increasing; gridpoint " + std::to_string(i + 1) + " is not");
  const Eigen::Index m = A.cols();
  auto shape = [&](const Eigen::Ref<const RowMatrixXd>& M, const char* name) {
    if (M.rows() != N || M.cols() != m)
      throw InputError(std::string(name) + " must have shape (N, m) = (" + std::to_string(N) + ", " +
                       std::to_string(m) + ") like A, got (" + std::to_string(M.rows()) + ", " +
                       std::to_string(M.cols()) + ")");
    if (!M.allFinite()) throw InputError(std::string(name) + " must be finite");
  };
  shape(A, "A");
  shape(B, "B");
  shape(C, "C");
  if (u_bounds.rows() != N) throw InputError("u_bounds must have shape (N, 2) = (" + std::to_string(N) + ", 2)");
  if (x_bounds.rows() != points)
    throw InputError("x_bounds must have shape (N + 1, 2) = (" + std::to_string(points) + ", 2)");
  if (u_bounds.hasNaN()) throw InputError("u_bounds must not be NaN");
  if (x_bounds.hasNaN()) throw InputError("x_bounds must not be NaN");
  if (!std::isfinite(x_start) || x_start < 0)
    throw InputError("x_start must be finite and >= 0, got " + number_text(x_start));
  if (!std::isfinite(x_end) || x_end < 0) throw InputError("x_end must be finite and >= 0, got " + number_text(x_end));
}

}  // namespace

HalfPlane normalized(const HalfPlane& h) {
  double norm = std::sqrt(h.a * h.a + h.b * h.b);  // (std::hypot is several times slower: one per row and stage)
  if (!std::isfinite(norm)) norm = std::hypot(h.a, h.b);  // the squares overflowed
  return norm > 0.0 ? HalfPlane{h.a / norm, h.b / norm, h.c / norm} : h;
}

Lp2dSolution solve_lp2d(double v_u, double v_x, const HalfPlane* rows, int m, const double lo[2], const double hi[2],
                        const int* order) {
  Lp2dSolution sol;
  if (!(lo[0] <= hi[0]) || !(lo[1] <= hi[1])) return sol;
  const double v[2] = {v_u, v_x};
  double p[2];
  // the box's best corner (a side of the box where the objective is level)
  p[0] = v[0] > kTiny ? hi[0] : lo[0];
  p[1] = v[1] > kTiny ? hi[1] : lo[1];
  sol.active[0] = v[0] > kTiny ? kUHigh : kULow;
  sol.active[1] = v[1] > kTiny ? kXHigh : kXLow;
  for (int k = 0; k < m; ++k) {
    const int r = order ? order[k] : k;
    const HalfPlane& h = rows[r];
    if (h.a * p[0] + h.b * p[1] - h.c < kTiny) continue;  // the optimum so far keeps row r: still the optimum
    int other = 0;
    if (!optimum_on_line(v, h, rows, order, k, lo, hi, p, &other)) return Lp2dSolution{};
    sol.active[0] = r;
    sol.active[1] = other;
  }
  sol.feasible = true;
  sol.u = p[0];
  sol.x = p[1];
  return sol;
}

bool max_u_at(double x, const HalfPlane* rows, int m, double u_lo, double u_hi, double* u) {
  double lo = u_lo, hi = u_hi;
  for (int k = 0; k < m; ++k) {
    const HalfPlane& h = rows[k];
    if (h.a > kTiny)
      hi = std::min(hi, (h.c - h.b * x) / h.a);
    else if (h.a < -kTiny)
      lo = std::max(lo, (h.c - h.b * x) / h.a);
  }
  if (lo > hi) return false;
  *u = hi;
  return true;
}

namespace {

// The backward and forward passes over the stages' rows (Stages: MatrixStages or CanonicalStages).
template <class Stages>
ToppRaResult passes(const Eigen::Ref<const Eigen::VectorXd>& grid, const Stages& stage,
                    const Eigen::Ref<const RowMatrixX2d>& u_bounds, const Eigen::Ref<const RowMatrixX2d>& x_bounds,
                    double x_start, double x_end) {
  const int N = static_cast<int>(grid.size() - 1);
  const int rows_count = static_cast<int>(stage.cols()) + 2;
  ToppRaResult res;
  res.x.assign(N + 1, kNaN);
  res.u.assign(N, kNaN);
  res.K = RowMatrixX2d::Constant(N + 1, 2, kNaN);
  std::vector<HalfPlane> rows(rows_count);
  std::vector<int> shuffled(rows_count), order;
  order.reserve(rows_count);
  std::iota(shuffled.begin(), shuffled.end(), 0);
  std::mt19937 rng(kOrderSeed);
  std::shuffle(shuffled.begin(), shuffled.end(), rng);
  double lo[2], hi[2];

  // the backward pass: K_N = {x_end}, K_i = [min x, max x] over stage i's LP with x + 2 delta u in K_{i+1}
  if (x_end < std::max(x_bounds(N, 0), 0.0) - kTiny || x_end > std::min(x_bounds(N, 1), kVarLimit) + kTiny) {
    res.status = ToppRaStatus::kUncontrollable;
    res.failed_at = N;
    return res;
  }
  res.K(N, 0) = res.K(N, 1) = x_end;
  int warm_max[2] = {-1, -1}, warm_min[2] = {-1, -1};
  for (int i = N - 1; i >= 0; --i) {
    stage.fill(rows, grid(i + 1) - grid(i), res.K(i + 1, 0), res.K(i + 1, 1), i);
    stage_box(u_bounds, x_bounds, i, lo, hi);
    warm_order(shuffled, warm_max, order);
    const Lp2dSolution top = solve_lp2d(-kTieWeight, 1.0, rows.data(), rows_count, lo, hi, order.data());
    warm_order(shuffled, warm_min, order);
    const Lp2dSolution bottom = solve_lp2d(kTieWeight, -1.0, rows.data(), rows_count, lo, hi, order.data());
    res.lp_count += 2;
    if (!top.feasible || !bottom.feasible) {
      res.status = ToppRaStatus::kUncontrollable;
      res.failed_at = i;
      return res;
    }
    std::copy(top.active, top.active + 2, warm_max);
    std::copy(bottom.active, bottom.active + 2, warm_min);
    res.K(i, 0) = std::max(bottom.x, 0.0);
    res.K(i, 1) = top.x;
  }

  // the forward pass: from x_start, the largest u that keeps x_{i+1} in K_{i+1}
  if (x_start + kStartTolerance < res.K(0, 0) || res.K(0, 1) + kStartTolerance < x_start) {
    res.status = ToppRaStatus::kStartOutside;
    res.failed_at = 0;
    return res;
  }
  res.x[0] = x_start;
  int tries = 0;
  for (int i = 0; i < N;) {
    const double delta = grid(i + 1) - grid(i);
    stage.fill(rows, delta, res.K(i + 1, 0), res.K(i + 1, 1), i);
    stage_box(u_bounds, x_bounds, i, lo, hi);
    double u = 0.0;
    ++res.lp_count;
    if (!max_u_at(res.x[i], rows.data(), rows_count, lo[0], hi[0], &u)) {
      // round-off put x_i just outside what stage i allows: lower it a little (toppra's remedy)
      if (tries++ < kMaxRetries) {
        res.x[i] = std::max(res.x[i] - kStepShrink, kRetryShare * res.x[i]);
        continue;
      }
      res.status = ToppRaStatus::kForwardFailed;
      res.failed_at = i;
      std::fill(res.x.begin() + i + 1, res.x.end(), kNaN);
      break;
    }
    tries = 0;
    const double next = res.x[i] + 2.0 * delta * u;
    // a hair below the optimum, and inside K_{i+1}, so that round-off never leaves the next stage without a u
    res.x[i + 1] = std::min(res.K(i + 1, 1), std::max(res.K(i + 1, 0), std::max(next - kStepShrink,
                                                                                 kStepShrinkShare * next)));
    ++i;
  }
  for (int i = 0; i < N; ++i) res.u[i] = (res.x[i + 1] - res.x[i]) / (2.0 * (grid(i + 1) - grid(i)));
  return res;
}

}  // namespace

ToppRaResult topp_ra(const Eigen::Ref<const Eigen::VectorXd>& grid, const Eigen::Ref<const RowMatrixXd>& A,
                     const Eigen::Ref<const RowMatrixXd>& B, const Eigen::Ref<const RowMatrixXd>& C,
                     const Eigen::Ref<const RowMatrixX2d>& u_bounds, const Eigen::Ref<const RowMatrixX2d>& x_bounds,
                     double x_start, double x_end) {
  validate(grid, A, B, C, u_bounds, x_bounds, x_start, x_end);
  const UnitRows rows(A, B, C);
  return passes(grid, MatrixStages{rows}, u_bounds, x_bounds, x_start, x_end);
}

ToppRaResult topp_ra_canonical(const Eigen::Ref<const Eigen::VectorXd>& grid, const Eigen::Ref<const RowMatrixXd>& P,
                               const Eigen::Ref<const RowMatrixXd>& Q, const Eigen::Ref<const RowMatrixXd>& R,
                               const Eigen::Ref<const Eigen::VectorXd>& x_max, double x_start, double x_end) {
  const Eigen::Index points = grid.size();
  if (points < 2) throw InputError("grid needs at least two gridpoints, got " + std::to_string(points));
  const Eigen::Index m = P.cols();
  if (points - 1 > std::numeric_limits<int>::max() / 2 || m > std::numeric_limits<int>::max() / 4 - 2)
    throw InputError("grid or rows too large for TOPP-RA");
  auto shape = [&](const Eigen::Ref<const RowMatrixXd>& M, const char* name) {
    if (M.rows() != points || M.cols() != m)
      throw InputError(std::string(name) + " must have shape (N + 1, m) = (" + std::to_string(points) + ", " +
                       std::to_string(m) + ") like P, got (" + std::to_string(M.rows()) + ", " +
                       std::to_string(M.cols()) + ")");
    if (!M.allFinite()) throw InputError(std::string(name) + " must be finite");
  };
  shape(P, "P");
  shape(Q, "Q");
  shape(R, "R");
  if (x_max.size() != points) throw InputError("x_max must have shape (N + 1,) = (" + std::to_string(points) + ",)");
  const Eigen::Index N = points - 1;
  RowMatrixX2d u_bounds(N, 2), x_bounds(points, 2);
  u_bounds.col(0).setConstant(-std::numeric_limits<double>::infinity());
  u_bounds.col(1).setConstant(std::numeric_limits<double>::infinity());
  x_bounds.col(0).setZero();
  x_bounds.col(1) = x_max;
  // the grid, x_max (NaN), x_start and x_end are checked as topp_ra checks them; its stage matrices are not made
  validate(grid, RowMatrixXd::Zero(N, 0), RowMatrixXd::Zero(N, 0), RowMatrixXd::Zero(N, 0), u_bounds, x_bounds,
           x_start, x_end);
  CanonicalStages stages{grid, P, Q, R};
  // as UnitRows: where some row's squares overflow (|a| or |b| > 1e154), every row is scaled by hypot (the rows are
  // looked at one by one only when their coefficients' bound leaves room for that: |a|, |b| < 1e153 cannot)
  const double big = m == 0 ? 0.0
                            : std::max(P.cwiseAbs().maxCoeff() + 2.0 * (grid(N) - grid(0)) * Q.cwiseAbs().maxCoeff(),
                                       Q.cwiseAbs().maxCoeff());
  for (Eigen::Index i = 0; i < N && !stages.overflow && !(big < 1e153); ++i) {
    const double twice = 2.0 * (grid(i + 1) - grid(i));
    for (Eigen::Index k = 0; k < m; ++k) {
      const double a0 = P(i, k), b0 = Q(i, k), a1 = P(i + 1, k) + twice * Q(i + 1, k), b1 = Q(i + 1, k);
      if (!std::isfinite(std::sqrt(a0 * a0 + b0 * b0)) || !std::isfinite(std::sqrt(a1 * a1 + b1 * b1))) {
        stages.overflow = true;
        break;
      }
    }
  }
  return passes(grid, stages, u_bounds, x_bounds, x_start, x_end);
}

}  // namespace snakehead
