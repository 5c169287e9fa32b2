#include "snakehead/dynamics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

#include "snakehead/kinematics.hpp"
#include "snakehead/model.hpp"
#include "snakehead/parallel_for.hpp"

namespace snakehead {

void RigidBodyChain::validate() const {
  const std::size_t L = mass.size();
  if (com.size() != L || inertia.size() != L) throw InputError("newton_euler: masses, coms, inertias differ in length");
  if (axis.size() != joint_child.size()) throw InputError("newton_euler: one axis per joint is needed");
  int previous = 0;
  for (int c : joint_child) {
    if (c <= previous || c >= static_cast<int>(L))
      throw InputError("newton_euler: joint child links must be increasing, after the root link and within the links");
    previous = c;
  }
}

namespace {

// Samples of a loop over configurations below which another thread costs more than it saves (a thread starts in
// ~20-50 us; a Newton-Euler sample of a 16-joint body takes ~2 us).
constexpr long kSamplesPerThread = 128;

// What one pass needs beside a sample's data: each link's joint (-1 for none), the first moving link, and room
// for the per-link quantities (sized once per call, not per sample).
struct NewtonEulerPass {
  explicit NewtonEulerPass(const RigidBodyChain& chain, long L) : R(L), p(L), omega(L), alpha(L), acc(L), z(L) {
    chain.validate();
    const long n = static_cast<long>(chain.joint_child.size());
    if (L != static_cast<long>(chain.mass.size())) throw InputError("newton_euler: frames hold another number of links");
    joint_of.assign(static_cast<std::size_t>(L), -1);
    for (long j = 0; j < n; ++j) joint_of[static_cast<std::size_t>(chain.joint_child[j])] = static_cast<int>(j);
    first = n > 0 ? chain.joint_child[0] : static_cast<int>(L);  // links before it: the still root
  }
  std::vector<int> joint_of;
  int first = 0;
  std::vector<Eigen::Matrix3d> R;
  std::vector<Eigen::Vector3d> p, omega, alpha, acc, z;

  // One sample: F (L x 4 x 4 row-major), v, a (n), share (L, or nullptr) -> tau (n), force, moment (3 each).
  void run(const RigidBodyChain& chain, const double* F, const double* v, const double* a, const double* share,
           const Eigen::Vector3d& gravity, double* tau, double* force, double* moment);
};

void NewtonEulerPass::run(const RigidBodyChain& chain, const double* F, const double* v, const double* a,
                          const double* share, const Eigen::Vector3d& gravity, double* tau, double* force,
                          double* moment) {
  const long L = static_cast<long>(R.size());
  const bool weighed = gravity.squaredNorm() > 0.0;
  for (long k = 0; k < L; ++k) {
    const Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>> M(F + k * 16);
    R[k] = M.topLeftCorner<3, 3>();
    p[k] = M.topRightCorner<3, 1>();
    omega[k].setZero();
    alpha[k].setZero();
    acc[k].setZero();
    z[k].setZero();
  }
  // forward: angular velocity and acceleration of each link, acceleration of each frame's origin
  for (long k = first; k < L; ++k) {
    const Eigen::Vector3d r = p[k] - p[k - 1];
    const Eigen::Vector3d& w = omega[k - 1];
    acc[k] = acc[k - 1] + alpha[k - 1].cross(r) + w.cross(w.cross(r));
    const int j = joint_of[k];
    if (j >= 0) {
      z[k] = R[k] * chain.axis[j];
      const Eigen::Vector3d wz = z[k] * v[j];
      omega[k] = w + wz;
      alpha[k] = alpha[k - 1] + z[k] * a[j] + w.cross(wz);
    } else {
      omega[k] = w;
      alpha[k] = alpha[k - 1];
    }
  }
  // backward: the wrench each link's parent exerts on it and on everything beyond it, about its frame's origin;
  // the weight's part apart, scaled link by link by the lifted share
  Eigen::Vector3d f_in = Eigen::Vector3d::Zero(), n_in = Eigen::Vector3d::Zero();
  Eigen::Vector3d f_g = Eigen::Vector3d::Zero(), n_g = Eigen::Vector3d::Zero();
  for (long k = L - 1; k >= first; --k) {
    if (k + 1 < L) {
      const Eigen::Vector3d d = p[k + 1] - p[k];
      n_in += d.cross(f_in);
      n_g += d.cross(f_g);
    }
    const double m = chain.mass[k];
    if (m > 0.0) {
      const Eigen::Vector3d rc = R[k] * chain.com[k];
      const Eigen::Vector3d ac = acc[k] + alpha[k].cross(rc) + omega[k].cross(omega[k].cross(rc));
      const Eigen::Matrix3d I = R[k] * chain.inertia[k] * R[k].transpose();
      const Eigen::Vector3d Iw = I * omega[k];
      f_in += m * ac;
      n_in += I * alpha[k] + omega[k].cross(Iw) + rc.cross(m * ac);
      if (weighed) {
        const Eigen::Vector3d hold = -m * gravity;  // holds the link against gravity
        f_g += hold;
        n_g += rc.cross(hold);
      }
    }
    if (share != nullptr) {
      f_g *= share[k];
      n_g *= share[k];
    }
    const int j = joint_of[k];
    if (j >= 0) tau[j] = (n_in + n_g).dot(z[k]);
  }
  const Eigen::Vector3d n_origin = first < L ? Eigen::Vector3d(n_in + p[first].cross(f_in)) : n_in;
  Eigen::Map<Eigen::Vector3d> force_out(force), moment_out(moment);
  force_out = f_in;
  moment_out = n_origin;
}

// The lifted shares of one sample's links (see LiftPoints) from its frames F (L x 4 x 4 row-major).
void lifted_shares(const LiftPoints& lift, const double* F, long L, double* share) {
  std::fill(share, share + L, 1.0);
  for (std::size_t i = 0; i < lift.link.size(); ++i) {
    const double* row = F + lift.link[i] * 16 + 8;  // the frame's z row: a point's height is row . (x, y, z, 1)
    double lowest = std::numeric_limits<double>::infinity();
    for (const Eigen::Vector3d& x : lift.points[i])
      lowest = std::min(lowest, row[0] * x[0] + row[1] * x[1] + row[2] * x[2] + row[3]);
    share[lift.link[i]] = std::clamp(lowest / lift.ramp, 0.0, 1.0);
  }
}

// Eq. 23 for one sample: sum_k m_k (p_k + R_k c_k) / M, link by link in chain order, in scalars (an Eigen product may
// use fused multiply-adds of its own where the target has them): the same numbers on any machine.
// coms: L x 3 (row-major). Massless links (marker frames) are left out.
void centre_of_mass_of(const double* F, const double* masses, const double* coms, long L, double* out) {
  double mc[3] = {0.0, 0.0, 0.0};
  double total = 0.0;
  for (long k = 0; k < L; ++k) {
    const double m = masses[k];
    if (m <= 0.0) continue;
    const double* M = F + k * 16;
    const double* c = coms + 3 * k;
    for (int i = 0; i < 3; ++i) {
      const double* row = M + 4 * i;
      double Rc = row[0] * c[0];
      Rc += row[1] * c[1];
      Rc += row[2] * c[2];
      const double x = row[3] + Rc;
      mc[i] += m * x;
    }
    total += m;
  }
  for (int i = 0; i < 3; ++i) out[i] = mc[i] / total;
}

}  // namespace

void newton_euler(const RigidBodyChain& chain, const double* frames, const double* qd, const double* qdd,
                  const double* share, const Eigen::Vector3d& gravity, long T, long L, double* tau,
                  double* force, double* moment) {
  if (T < 0) throw InputError("newton_euler: negative sample count");
  NewtonEulerPass pass(chain, L);
  const long n = static_cast<long>(chain.joint_child.size());
  parallel_for(T, kSamplesPerThread, [&](long begin, long end) {
    NewtonEulerPass own(pass);
    for (long t = begin; t < end; ++t)
      own.run(chain, frames + t * L * 16, qd + t * n, qdd + t * n, share != nullptr ? share + t * L : nullptr,
              gravity, tau + t * n, force + 3 * t, moment + 3 * t);
  });
}

void LiftPoints::validate(long L) const {
  if (points.size() != link.size()) throw InputError("newton_euler_along: one point set per lifted link is needed");
  if (!(ramp > 0.0)) throw InputError("newton_euler_along: the lift ramp must be > 0");
  for (std::size_t i = 0; i < link.size(); ++i) {
    if (link[i] < 0 || link[i] >= L) throw InputError("newton_euler_along: a lifted link is not a link of the chain");
    if (points[i].empty()) throw InputError("newton_euler_along: a lifted link has no points");
  }
}

void newton_euler_along(const ChainModel& model, const Eigen::Matrix4d& origin, const RigidBodyChain& chain,
                        const LiftPoints* lift, const double* q, const double* qd, const double* qdd,
                        const Eigen::Vector3d& gravity, long T, double* tau, double* force, double* moment,
                        double* com) {
  if (T < 0) throw InputError("newton_euler_along: negative sample count");
  const long L = static_cast<long>(model.links().size());
  const long n = static_cast<long>(model.n_joints());
  if (n != static_cast<long>(chain.joint_child.size()))
    throw InputError("newton_euler_along: the model and the chain have other joint counts");
  NewtonEulerPass pass(chain, L);
  if (lift != nullptr) lift->validate(L);
  if (chain.mass.size() > 0 && !(std::accumulate(chain.mass.begin(), chain.mass.end(), 0.0) > 0.0))
    throw InputError("newton_euler_along: the body has no mass");
  std::vector<double> coms(3 * chain.com.size());
  for (std::size_t k = 0; k < chain.com.size(); ++k)
    for (int i = 0; i < 3; ++i) coms[3 * k + i] = chain.com[k][i];
  // the samples are independent: split over the core's threads, each with its own pass and buffers
  parallel_for(T, kSamplesPerThread, [&](long begin, long end) {
    NewtonEulerPass own(pass);
    Frames local;
    std::vector<double> F(static_cast<std::size_t>(L) * 16), share(static_cast<std::size_t>(L));
    for (long t = begin; t < end; ++t) {
      world_link_frames(model, origin, Eigen::Map<const Eigen::VectorXd>(q + t * n, n), local, F.data());
      if (lift != nullptr) lifted_shares(*lift, F.data(), L, share.data());
      own.run(chain, F.data(), qd + t * n, qdd + t * n, lift != nullptr ? share.data() : nullptr, gravity,
              tau + t * n, force + 3 * t, moment + 3 * t);
      centre_of_mass_of(F.data(), chain.mass.data(), coms.data(), L, com + 3 * t);
    }
  });
}

void center_of_mass(const double* frames, const double* masses, const double* coms, long T, long L, double* com) {
  if (T < 0 || L < 0) throw InputError("center_of_mass: negative sample or link count");
  double total = 0.0;
  for (long k = 0; k < L; ++k) {
    if (!std::isfinite(masses[k]) || masses[k] < 0.0) throw InputError("center_of_mass: masses must be finite and >= 0");
    if (masses[k] > 0.0) total += masses[k];
  }
  if (!(total > 0.0)) throw InputError("center_of_mass: the body has no mass");
  for (long t = 0; t < T; ++t) centre_of_mass_of(frames + t * L * 16, masses, coms, L, com + 3 * t);
}

void momenta(const RigidBodyChain& chain, const double* frames, const double* qd, long T, long L, double* linear,
             double* angular, double* com) {
  chain.validate();
  const long n = static_cast<long>(chain.joint_child.size());
  if (L != static_cast<long>(chain.mass.size())) throw InputError("momenta: frames hold another number of links");
  if (T < 0) throw InputError("momenta: negative sample count");
  double total = 0.0;
  for (double m : chain.mass) total += m;
  if (!(total > 0.0)) throw InputError("momenta: the body has no mass");
  using M4 = Eigen::Matrix<double, 4, 4, Eigen::RowMajor>;
  for (long t = 0; t < T; ++t) {
    const double* F = frames + t * L * 16;
    const double* v = qd + t * n;
    Eigen::Vector3d omega = Eigen::Vector3d::Zero();  // sum of z_i qd_i over the joints passed so far (Eq. 26)
    Eigen::Vector3d wxo = Eigen::Vector3d::Zero();    // sum of (z_i qd_i) x o_i over the same joints
    Eigen::Vector3d P = Eigen::Vector3d::Zero(), Lm = Eigen::Vector3d::Zero(), mc = Eigen::Vector3d::Zero();
    long j = 0;
    for (long k = 0; k < L; ++k) {
      const Eigen::Map<const M4> M(F + k * 16);
      while (j < n && chain.joint_child[j] <= k) {  // joint j moves this link and every later one
        const Eigen::Map<const M4> J(F + chain.joint_child[j] * 16);
        const Eigen::Vector3d w = J.topLeftCorner<3, 3>() * chain.axis[j] * v[j];
        omega += w;
        wxo += w.cross(J.topRightCorner<3, 1>());
        ++j;
      }
      const double m = chain.mass[k];
      if (m <= 0.0) continue;  // marker frames carry no mass
      const Eigen::Matrix3d R = M.topLeftCorner<3, 3>();
      const Eigen::Vector3d c = M.topRightCorner<3, 1>() + R * chain.com[k];
      const Eigen::Vector3d Pk = m * (omega.cross(c) - wxo);  // Eqs. 25, 27, 28
      P += Pk;                                                 // Eq. 29
      Lm += c.cross(Pk) + R * (chain.inertia[k] * (R.transpose() * omega));  // Eqs. 30, 31
      mc += m * c;
    }
    Eigen::Map<Eigen::Vector3d>(linear + 3 * t) = P;
    Eigen::Map<Eigen::Vector3d>(angular + 3 * t) = Lm;
    Eigen::Map<Eigen::Vector3d>(com + 3 * t) = mc / total;
  }
}

RigidBodyChain chain_dynamics(const ChainModel& model) {
  RigidBodyChain chain;
  for (const auto& s : model.segments()) {
    chain.joint_child.push_back(model.link_index(s.link));
    chain.axis.push_back(s.axis);
  }
  for (const auto& link : model.links()) {
    chain.mass.push_back(link.mass);
    chain.com.push_back(link.com);
    chain.inertia.push_back(link.inertia);
  }
  return chain;
}

}  // namespace snakehead
