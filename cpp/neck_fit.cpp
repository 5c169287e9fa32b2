#include "snakehead/neck_fit.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "snakehead/kinematics.hpp"

namespace snakehead {
namespace {

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d s;
  s << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return s;
}

// Eq. 22's six residuals r = (P_a - P_d, sqrt(h) r_d x r_a) at q and, when J is given, their Jacobian (6 x n):
// d(P_a)/dq = R0 Jv, d(r_a)/dq = (R0 Jw) x r_a.
class Residual {
 public:
  Residual(const ChainModel& neck, const Eigen::Isometry3d& P0, const Eigen::Vector3d& P_d, const Eigen::Vector3d& r_d,
           double h)
      : neck_(neck), R0_(P0.linear()), p0_(P0.translation()), P_d_(P_d), S_rd_(skew(r_d)), sqrt_h_(std::sqrt(h)) {}

  void operator()(const Eigen::VectorXd& q, Eigen::Matrix<double, 6, 1>& r, Eigen::MatrixXd* J) {
    Eigen::Isometry3d tip;
    if (J != nullptr) {
      tip_jacobian(neck_, q, jac_, tip);
    } else {
      tip = forward_kinematics(neck_, q);
    }
    const Eigen::Vector3d ra = R0_ * tip.linear().col(0);
    r.head<3>() = R0_ * tip.translation() + p0_ - P_d_;
    r.tail<3>() = sqrt_h_ * (S_rd_ * ra);
    if (J == nullptr) return;
    J->resize(6, q.size());
    J->topRows<3>() = R0_ * jac_.topRows<3>();
    J->bottomRows<3>() = sqrt_h_ * (S_rd_ * (-skew(ra) * (R0_ * jac_.bottomRows<3>())));
  }

 private:
  const ChainModel& neck_;
  Eigen::Matrix3d R0_;
  Eigen::Vector3d p0_, P_d_;
  Eigen::Matrix3d S_rd_;
  double sqrt_h_;
  Jacobian jac_;
};

// Levenberg-Marquardt on |r(q)|^2 with the steps projected onto the box [lo, hi]; joints held at a bound by the
// gradient (the active set) do not step.
NeckFit bounded_least_squares(Residual& residual, Eigen::VectorXd q, const Eigen::VectorXd& lo, const Eigen::VectorXd& hi,
                              const NeckFitSettings& s) {
  const Eigen::Index n = q.size();
  Eigen::Matrix<double, 6, 1> r, r_new;
  Eigen::MatrixXd J, J_new;
  residual(q, r, &J);
  double cost = r.squaredNorm();
  double lam = 1e-3;
  for (int it = 0; it < s.iterations; ++it) {
    const Eigen::VectorXd g = J.transpose() * r;
    std::vector<Eigen::Index> free;
    for (Eigen::Index j = 0; j < n; ++j)
      if (!((q[j] <= lo[j] && g[j] > 0) || (q[j] >= hi[j] && g[j] < 0))) free.push_back(j);
    if (free.empty()) break;
    const auto m = static_cast<Eigen::Index>(free.size());
    Eigen::MatrixXd Jf(6, m);
    Eigen::VectorXd gf(m);
    for (Eigen::Index k = 0; k < m; ++k) {
      Jf.col(k) = J.col(free[k]);
      gf[k] = g[free[k]];
    }
    Eigen::MatrixXd A = Jf.transpose() * Jf;
    A.diagonal().array() += lam;
    const Eigen::VectorXd step_free = -A.partialPivLu().solve(gf);
    Eigen::VectorXd q_new = q;
    for (Eigen::Index k = 0; k < m; ++k) q_new[free[k]] += step_free[k];
    q_new = q_new.cwiseMax(lo).cwiseMin(hi);
    residual(q_new, r_new, &J_new);
    const double cost_new = r_new.squaredNorm();
    if (cost_new < cost) {
      // the neck needs no more than ~1e-9 rad: the head's IK absorbs what the neck leaves
      const bool done = cost - cost_new < s.tolerance * std::max(cost, 1e-30) || (q_new - q).cwiseAbs().maxCoeff() < 1e-9;
      q.swap(q_new);
      r = r_new;
      J.swap(J_new);
      cost = cost_new;
      lam = std::max(lam / 10, 1e-12);
      if (done) break;
    } else {
      lam *= 10;
      if (lam > 1e8) break;
    }
  }
  return {q, cost};
}

// The grid's point of least cost: grid_points values per joint, in numpy.meshgrid's order ("xy": the second joint's
// values outermost, then the first's, then the others in order), the first of equal costs.
Eigen::VectorXd best_grid_point(Residual& residual, const Eigen::VectorXd& lo, const Eigen::VectorXd& hi,
                                const NeckFitSettings& s) {
  const Eigen::Index n = lo.size();
  std::vector<Eigen::VectorXd> values(static_cast<std::size_t>(n));
  for (Eigen::Index j = 0; j < n; ++j)
    values[static_cast<std::size_t>(j)] =
        Eigen::VectorXd::LinSpaced(s.grid_points, s.grid_fraction * lo[j], s.grid_fraction * hi[j]);
  std::vector<Eigen::Index> order(static_cast<std::size_t>(n));  // slowest-varying joint first
  for (Eigen::Index j = 0; j < n; ++j) order[static_cast<std::size_t>(j)] = j;
  if (n >= 2) std::swap(order[0], order[1]);
  std::vector<int> index(static_cast<std::size_t>(n), 0);
  Eigen::VectorXd q(n), best;
  Eigen::Matrix<double, 6, 1> r;
  double best_cost = std::numeric_limits<double>::infinity();
  for (;;) {
    for (Eigen::Index j = 0; j < n; ++j) q[j] = values[static_cast<std::size_t>(j)][index[static_cast<std::size_t>(j)]];
    residual(q, r, nullptr);
    if (r.squaredNorm() < best_cost || best.size() == 0) {
      best_cost = r.squaredNorm();
      best = q;
    }
    Eigen::Index k = n - 1;  // the next index, the last of `order` fastest
    for (; k >= 0; --k) {
      int& i = index[static_cast<std::size_t>(order[static_cast<std::size_t>(k)])];
      if (++i < s.grid_points) break;
      i = 0;
    }
    if (k < 0) break;
  }
  return best;
}

void check_inputs(const ChainModel& neck, const Eigen::Isometry3d& P0, const Eigen::Vector3d& P_d,
                  const Eigen::Vector3d& r_d, const NeckFitSettings& s, const Eigen::VectorXd* q_init) {
  if (neck.n_joints() < 1) throw InputError("fit_neck: the neck chain has no joints");
  if (!P0.matrix().allFinite() || !P_d.allFinite() || !r_d.allFinite())
    throw InputError("fit_neck: P0_frame, P_d and r_d must be finite");
  if (!(s.h > 0.0) || !std::isfinite(s.h)) throw InputError("fit_neck: h must be > 0");
  if (s.grid_points < 1 || s.grid_points > 64) throw InputError("fit_neck: grid_points must be within [1, 64]");
  if (!(s.grid_fraction >= 0.0 && s.grid_fraction <= 1.0)) throw InputError("fit_neck: grid_fraction must be in [0, 1]");
  if (s.iterations < 0 || s.iterations > 100000) throw InputError("fit_neck: iterations must be within [0, 100000]");
  if (!(s.tolerance >= 0.0) || !(s.continuity_tolerance >= 0.0) || !std::isfinite(s.tolerance) ||
      !std::isfinite(s.continuity_tolerance))
    throw InputError("fit_neck: the tolerances must be finite and >= 0");
  if (std::pow(static_cast<double>(s.grid_points), static_cast<double>(neck.n_joints())) > 1e7)
    throw InputError("fit_neck: the grid would hold more than 1e7 points (too many neck joints for grid_points)");
  if (!neck.lower().allFinite() || !neck.upper().allFinite())
    throw InputError("fit_neck: the neck's joints need finite limits (the grid spans them)");
  if (q_init != nullptr && (q_init->size() != neck.n_joints() || !q_init->allFinite()))
    throw InputError("fit_neck: q_init must hold one finite angle per neck joint");
}

}  // namespace

NeckFit fit_neck(const ChainModel& neck, const Eigen::Isometry3d& P0_frame, const Eigen::Vector3d& P_d,
                 const Eigen::Vector3d& r_d, const NeckFitSettings& settings, const Eigen::VectorXd* q_init) {
  check_inputs(neck, P0_frame, P_d, r_d, settings, q_init);
  const Eigen::VectorXd& lo = neck.lower();
  const Eigen::VectorXd& hi = neck.upper();
  Residual residual(neck, P0_frame, P_d, r_d, settings.h);
  std::vector<Eigen::VectorXd> starts;
  if (q_init != nullptr) starts.push_back(*q_init);
  starts.push_back(best_grid_point(residual, lo, hi, settings));
  NeckFit best;
  for (std::size_t k = 0; k < starts.size(); ++k) {
    NeckFit fit = bounded_least_squares(residual, starts[k].cwiseMax(lo).cwiseMin(hi), lo, hi, settings);
    // continuity: the solution reached from q_init (tried first) is kept unless another start is clearly better, so
    // that nearby targets give nearby necks instead of jumping between minima
    if (k == 0 || fit.cost < best.cost - settings.continuity_tolerance) best = std::move(fit);
  }
  return best;
}

}  // namespace snakehead
