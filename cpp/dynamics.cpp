#include "snakehead/dynamics.hpp"

#include <string>

#include "snakehead/model.hpp"

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

void newton_euler(const RigidBodyChain& chain, const double* frames, const double* qd, const double* qdd,
                  const double* share, const Eigen::Vector3d& gravity, long T, long L, double* tau,
                  double* force, double* moment) {
  chain.validate();
  const long n = static_cast<long>(chain.joint_child.size());
  if (L != static_cast<long>(chain.mass.size())) throw InputError("newton_euler: frames hold another number of links");
  if (T < 0) throw InputError("newton_euler: negative sample count");
  std::vector<int> joint_of(static_cast<std::size_t>(L), -1);
  for (long j = 0; j < n; ++j) joint_of[static_cast<std::size_t>(chain.joint_child[j])] = static_cast<int>(j);
  const int first = n > 0 ? chain.joint_child[0] : static_cast<int>(L);  // links before it: the still root
  const bool weighed = gravity.squaredNorm() > 0.0;
  std::vector<Eigen::Matrix3d> R(L);
  std::vector<Eigen::Vector3d> p(L), omega(L), alpha(L), acc(L), z(L);
  for (long t = 0; t < T; ++t) {
    const double* F = frames + t * L * 16;
    for (long k = 0; k < L; ++k) {
      const Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>> M(F + k * 16);
      R[k] = M.topLeftCorner<3, 3>();
      p[k] = M.topRightCorner<3, 1>();
      omega[k].setZero();
      alpha[k].setZero();
      acc[k].setZero();
      z[k].setZero();
    }
    const double* v = qd + t * n;
    const double* a = qdd + t * n;
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
    double* out = tau + t * n;
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
        const double s = share[t * L + k];
        f_g *= s;
        n_g *= s;
      }
      const int j = joint_of[k];
      if (j >= 0) out[j] = (n_in + n_g).dot(z[k]);
    }
    const Eigen::Vector3d n_origin = first < L ? Eigen::Vector3d(n_in + p[first].cross(f_in)) : n_in;
    Eigen::Map<Eigen::Vector3d>(force + 3 * t) = f_in;
    Eigen::Map<Eigen::Vector3d>(moment + 3 * t) = n_origin;
  }
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

}  // namespace snakehead
