#include "snakehead/kinematics.hpp"

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

void world_link_frames(const ChainModel& model, const Eigen::Matrix4d& origin, const Eigen::Ref<const Eigen::VectorXd>& q,
                       Frames& local, double* out) {
  link_frames(model, q, local);
  for (std::size_t k = 0; k < local.size(); ++k)
    Eigen::Map<Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(out + 16 * k) = origin * local[k].matrix();
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
