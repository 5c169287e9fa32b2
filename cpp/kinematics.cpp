#include "snakehead/kinematics.hpp"

#include <cmath>

#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainjnttojacsolver.hpp>

namespace snakehead {
namespace {

// The joint's own motion: a rotation about, or a translation along, the unit axis.
inline Eigen::Isometry3d joint_motion(const SegmentGeometry& s, double q) {
  Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
  if (s.prismatic)
    m.translation() = s.axis * q;
  else
    m.linear() = Eigen::AngleAxisd(q, s.axis).toRotationMatrix();
  return m;
}

KDL::JntArray to_jnt(const Eigen::Ref<const Eigen::VectorXd>& q) {
  KDL::JntArray a(static_cast<unsigned>(q.size()));
  a.data = q;
  return a;
}

}  // namespace

Eigen::Isometry3d forward_kinematics(const ChainModel& model, const Eigen::Ref<const Eigen::VectorXd>& q) {
  Eigen::Isometry3d frame = Eigen::Isometry3d::Identity();
  const auto& segs = model.segments();
  for (std::size_t i = 0; i < segs.size(); ++i) frame = frame * segs[i].pre * joint_motion(segs[i], q[i]) * segs[i].post;
  return frame;
}

void link_frames(const ChainModel& model, const Eigen::Ref<const Eigen::VectorXd>& q, Frames& out) {
  const auto& segs = model.segments();
  Frames tips(segs.size());
  Eigen::Isometry3d frame = Eigen::Isometry3d::Identity();
  for (std::size_t i = 0; i < segs.size(); ++i) {
    frame = frame * segs[i].pre * joint_motion(segs[i], q[i]) * segs[i].post;
    tips[i] = frame;
  }
  const auto& links = model.links();
  out.resize(links.size());
  for (std::size_t k = 0; k < links.size(); ++k)
    out[k] = links[k].segment < 0 ? links[k].offset : tips[links[k].segment] * links[k].offset;
}

namespace {

// M is the identity exactly (Eigen's isIdentity(0.0), without its general tolerance arithmetic: it took a tenth of
// the ZMP check's time, called for every fixed transform of every sample).
inline bool exactly_identity(const Eigen::Matrix3d& M) {
  const double* d = M.data();
  return d[0] == 1.0 && d[4] == 1.0 && d[8] == 1.0 && d[1] == 0.0 && d[2] == 0.0 && d[3] == 0.0 && d[5] == 0.0 &&
         d[6] == 0.0 && d[7] == 0.0;
}

// (R, p) <- (R, p) * T: a fixed transform of the chain, most of them pure translations (their rotation not applied).
inline void compose(Eigen::Matrix3d& R, Eigen::Vector3d& p, const Eigen::Isometry3d& T) {
  p += R * T.translation();
  if (!exactly_identity(T.linear())) R = R * T.linear();
}

// R <- R * Rot(axis, q). About a coordinate axis (URDF joints mostly are) only two columns change, by the angle's
// cosine and sine; any other axis through Eigen's angle-axis matrix.
inline void rotate(Eigen::Matrix3d& R, const Eigen::Vector3d& axis, double q) {
  for (int k = 0; k < 3; ++k) {
    const int i = (k + 1) % 3, j = (k + 2) % 3;  // about e_k: e_i -> c e_i + s e_j, e_j -> c e_j - s e_i
    if (std::abs(axis[k]) != 1.0 || axis[i] != 0.0 || axis[j] != 0.0) continue;
    const double a = axis[k] > 0.0 ? q : -q, c = std::cos(a), s = std::sin(a);
    const Eigen::Vector3d ci = R.col(i), cj = R.col(j);
    R.col(i) = c * ci + s * cj;
    R.col(j) = c * cj - s * ci;
    return;
  }
  R = R * Eigen::AngleAxisd(q, axis).toRotationMatrix();
}

}  // namespace

void world_link_frames(const ChainModel& model, const Eigen::Matrix4d& origin, const Eigen::Ref<const Eigen::VectorXd>& q,
                       Frames& local, double* out) {
  using Row4 = Eigen::Matrix<double, 4, 4, Eigen::RowMajor>;
  const auto& links = model.links();
  if (origin.row(3) != Eigen::RowVector4d(0.0, 0.0, 0.0, 1.0)) {  // not a rigid placement: the general product
    link_frames(model, q, local);
    for (std::size_t k = 0; k < local.size(); ++k) Eigen::Map<Row4>(out + 16 * k) = origin * local[k].matrix();
    return;
  }
  // the chain from the origin on (origin * link_frames(q), the origin folded in first), the joints' tips in `local`
  const auto& segs = model.segments();
  local.resize(segs.size() + 1);
  Eigen::Matrix3d R = origin.topLeftCorner<3, 3>();
  Eigen::Vector3d p = origin.topRightCorner<3, 1>();
  local.back().linear() = R;  // the base frame's pose, for links before the first joint
  local.back().translation() = p;
  for (std::size_t i = 0; i < segs.size(); ++i) {
    compose(R, p, segs[i].pre);
    if (segs[i].prismatic)
      p += R * (segs[i].axis * q[static_cast<Eigen::Index>(i)]);
    else
      rotate(R, segs[i].axis, q[static_cast<Eigen::Index>(i)]);
    compose(R, p, segs[i].post);
    local[i].linear() = R;
    local[i].translation() = p;
  }
  for (std::size_t k = 0; k < links.size(); ++k) {
    const Eigen::Isometry3d& tip = local[links[k].segment < 0 ? segs.size() : static_cast<std::size_t>(links[k].segment)];
    Eigen::Map<Row4> f(out + 16 * k);
    const Eigen::Isometry3d& offset = links[k].offset;  // an isometry's last row is (0, 0, 0, 1)
    if (exactly_identity(offset.linear()) && offset.translation().x() == 0.0 && offset.translation().y() == 0.0 &&
        offset.translation().z() == 0.0)
      f = tip.matrix();
    else
      f = (tip * links[k].offset).matrix();
    f.row(3) << 0.0, 0.0, 0.0, 1.0;
  }
}

void tip_jacobian(const ChainModel& model, const Eigen::Ref<const Eigen::VectorXd>& q, Jacobian& jac,
                  Eigen::Isometry3d& tip) {
  const auto& segs = model.segments();
  const int n = static_cast<int>(segs.size());
  jac.resize(6, n);
  // First pass: joint axes and origins in the base frame; the tip comes out at the end.
  Eigen::Isometry3d frame = Eigen::Isometry3d::Identity();
  for (int i = 0; i < n; ++i) {
    const Eigen::Isometry3d joint = frame * segs[i].pre * joint_motion(segs[i], q[i]);
    jac.block<3, 1>(3, i) = joint.linear() * segs[i].axis;       // axis, provisional
    jac.block<3, 1>(0, i) = joint.translation();                 // origin, provisional
    frame = joint * segs[i].post;
  }
  tip = frame;
  const Eigen::Vector3d p = tip.translation();
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d z = jac.block<3, 1>(3, i);
    if (segs[i].prismatic) {
      jac.block<3, 1>(0, i) = z;
      jac.block<3, 1>(3, i).setZero();
    } else {
      jac.block<3, 1>(0, i) = z.cross(p - jac.block<3, 1>(0, i));
    }
  }
}

Eigen::Isometry3d kdl_forward_kinematics(const ChainModel& model, const Eigen::Ref<const Eigen::VectorXd>& q) {
  KDL::ChainFkSolverPos_recursive solver(model.kdl_chain());
  KDL::Frame f;
  if (solver.JntToCart(to_jnt(q), f) < 0) throw std::runtime_error("KDL forward kinematics failed");
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) t.matrix()(r, c) = f.M(r, c);
    t.matrix()(r, 3) = f.p[r];
  }
  return t;
}

Jacobian kdl_jacobian(const ChainModel& model, const Eigen::Ref<const Eigen::VectorXd>& q) {
  KDL::ChainJntToJacSolver solver(model.kdl_chain());
  KDL::Jacobian j(model.n_joints());
  if (solver.JntToJac(to_jnt(q), j) < 0) throw std::runtime_error("KDL Jacobian failed");
  return j.data;
}

}  // namespace snakehead
