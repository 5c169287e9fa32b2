#include "snakehead/model.hpp"

#include <urdf_model/model.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <sstream>

#include "snakehead/limits.hpp"
#include "snakehead/urdf_input.hpp"

namespace snakehead {
namespace {

Eigen::Isometry3d to_isometry(const urdf::Pose& pose) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  double x, y, z, w;
  pose.rotation.getQuaternion(x, y, z, w);
  t.linear() = Eigen::Quaterniond(w, x, y, z).normalized().toRotationMatrix();
  t.translation() = Eigen::Vector3d(pose.position.x, pose.position.y, pose.position.z);
  return t;
}

KDL::Frame to_kdl(const Eigen::Isometry3d& t) {
  const Eigen::Matrix3d& r = t.linear();
  return KDL::Frame(KDL::Rotation(r(0, 0), r(0, 1), r(0, 2), r(1, 0), r(1, 1), r(1, 2), r(2, 0), r(2, 1), r(2, 2)),
                    KDL::Vector(t.translation().x(), t.translation().y(), t.translation().z()));
}

KDL::Vector to_kdl(const Eigen::Vector3d& v) { return KDL::Vector(v.x(), v.y(), v.z()); }

std::string vector_text(double x, double y, double z) {
  return number_text(x) + " " + number_text(y) + " " + number_text(z);
}

// A link's mass and inertia must describe a body: mass >= 0, the inertia symmetric positive semidefinite with
// principal moments that satisfy the triangle inequality (A + B >= C, as for any distribution of mass).
void check_inertial(const std::string& link, double mass, const Eigen::Matrix3d& inertia) {
  const std::string where = "link '" + link + "' <inertial>: ";
  if (!std::isfinite(mass) || mass < 0)
    throw InputError(where + "mass must be a finite number of kg >= 0, got " + number_text(mass));
  if (!inertia.allFinite()) throw InputError(where + "the inertia holds a non-finite value");
  const Eigen::Vector3d moments =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(inertia, Eigen::EigenvaluesOnly).eigenvalues();  // ascending
  const double tolerance = 1e-9 * moments.cwiseAbs().maxCoeff();
  const std::string got = " (principal moments " + vector_text(moments[0], moments[1], moments[2]) + " kg m^2)";
  if (moments[0] < -tolerance) throw InputError(where + "the inertia is not positive semidefinite" + got);
  if (moments[0] + moments[1] < moments[2] - tolerance)
    throw InputError(where + "the inertia's principal moments violate the triangle inequality A + B >= C" + got);
}

// Collision shapes must have positive, finite sizes (a box of size 0 or -1 is not a body).
void check_collision(const std::string& link, const urdf::Collision& collision) {
  if (!collision.geometry) return;
  const std::string where = "link '" + link + "' <collision>: ";
  const urdf::Geometry& g = *collision.geometry;
  auto positive = [](double v) { return std::isfinite(v) && v > 0; };
  if (g.type == urdf::Geometry::BOX) {
    const auto& d = static_cast<const urdf::Box&>(g).dim;
    if (!positive(d.x) || !positive(d.y) || !positive(d.z))
      throw InputError(where + "a box size must be three positive numbers of metres, got " + vector_text(d.x, d.y, d.z));
  } else if (g.type == urdf::Geometry::SPHERE) {
    const double r = static_cast<const urdf::Sphere&>(g).radius;
    if (!positive(r)) throw InputError(where + "a sphere radius must be positive, got " + number_text(r));
  } else if (g.type == urdf::Geometry::CYLINDER) {
    const auto& c = static_cast<const urdf::Cylinder&>(g);
    if (!positive(c.radius) || !positive(c.length))
      throw InputError(where + "a cylinder's radius and length must be positive, got " + number_text(c.radius) + " and " +
                       number_text(c.length));
  } else if (g.type == urdf::Geometry::MESH) {
    const auto& m = static_cast<const urdf::Mesh&>(g);
    if (m.filename.empty()) throw InputError(where + "a mesh needs a filename");
    if (!positive(m.scale.x) || !positive(m.scale.y) || !positive(m.scale.z))
      throw InputError(where + "a mesh scale must be three positive numbers, got " +
                       vector_text(m.scale.x, m.scale.y, m.scale.z));
  }
}

// A checked <collision> element as the model keeps it.
CollisionElement collision_element(const urdf::Collision& collision) {
  CollisionElement e;
  e.origin = to_isometry(collision.origin);
  e.size.setZero();
  const urdf::Geometry& g = *collision.geometry;
  switch (g.type) {
    case urdf::Geometry::BOX: {
      const auto& d = static_cast<const urdf::Box&>(g).dim;
      e.kind = CollisionKind::Box;
      e.size = Eigen::Vector3d(d.x, d.y, d.z);
      break;
    }
    case urdf::Geometry::CYLINDER: {
      const auto& c = static_cast<const urdf::Cylinder&>(g);
      e.kind = CollisionKind::Cylinder;
      e.size = Eigen::Vector3d(c.radius, c.length, 0.0);
      break;
    }
    case urdf::Geometry::SPHERE:
      e.kind = CollisionKind::Sphere;
      e.size = Eigen::Vector3d(static_cast<const urdf::Sphere&>(g).radius, 0.0, 0.0);
      break;
    case urdf::Geometry::MESH: {
      const auto& m = static_cast<const urdf::Mesh&>(g);
      e.kind = CollisionKind::Mesh;
      e.size = Eigen::Vector3d(m.scale.x, m.scale.y, m.scale.z);
      e.filename = m.filename;
      break;
    }
  }
  return e;
}

void fill_inertial(const urdf::Link& link, LinkInfo& info) {
  info.mass = 0.0;
  info.com.setZero();
  info.inertia.setZero();
  if (link.inertial) {
    const urdf::Inertial& in = *link.inertial;
    Eigen::Matrix3d local;
    local << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
    check_inertial(link.name, in.mass, local);
    const Eigen::Isometry3d origin = to_isometry(in.origin);
    info.mass = in.mass;
    info.com = origin.translation();
    info.inertia = origin.linear() * local * origin.linear().transpose();
  }
  for (const auto& collision : link.collision_array) {
    if (!collision) continue;
    check_collision(link.name, *collision);
    if (collision->geometry) info.collisions.push_back(collision_element(*collision));
  }
}

// FNV-1a over a canonical text of the kinematics.
std::string digest(const std::string& text) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : text) {
    h ^= c;
    h *= 1099511628211ull;
  }
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

void append(std::ostringstream& os, const Eigen::Isometry3d& t) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) os << t.matrix()(r, c) << ' ';
}

}  // namespace

namespace {

// The text of a URDF given as an XML document (its first non-blank character is '<') or a file path.
std::string document_text(const std::string& urdf) {
  const auto first = urdf.find_first_not_of(" \t\r\n");
  if (first != std::string::npos && urdf[first] == '<') return urdf;
  return read_urdf_file(urdf);
}

}  // namespace

ChainModel ChainModel::from_urdf(const std::string& urdf, const std::string& base, const std::string& tip) {
  return from_urdf_string(document_text(urdf), base, tip);
}

ChainModel ChainModel::from_urdf_file(const std::string& path, const std::string& base, const std::string& tip) {
  return from_urdf_string(read_urdf_file(path), base, tip);
}

std::string urdf_root_link(const std::string& urdf) {
  const auto robot = parse_urdf(document_text(urdf));  // checked, and urdfdom's complaints as InputError
  const auto root = robot->getRoot();
  if (!root) throw InputError("the URDF has no root link");
  return root->name;
}

ChainModel ChainModel::from_urdf_string(const std::string& xml, const std::string& base, const std::string& tip) {
  const urdf::ModelInterfaceSharedPtr robot = parse_urdf(xml);  // checked, and urdfdom's complaints as InputError
  if (base == tip) throw InputError("base and tip are the same link '" + base + "': a chain needs two links");
  const auto base_link = robot->getLink(base);
  if (!base_link) throw InputError("unknown base link '" + base + "' in URDF robot '" + robot->getName() + "'");
  auto link = robot->getLink(tip);
  if (!link) throw InputError("unknown tip link '" + tip + "' in URDF robot '" + robot->getName() + "'");

  // Walk up from the tip to the base.
  std::vector<urdf::LinkConstSharedPtr> path{link};
  while (link->name != base) {
    link = link->getParent();
    if (!link)
      throw InputError("base link '" + base + "' is not an ancestor of tip link '" + tip + "': no chain joins them");
    path.push_back(link);
  }
  std::reverse(path.begin(), path.end());

  ChainModel m;
  m.base_ = base;
  m.tip_ = tip;
  LinkInfo base_info;
  base_info.name = base;
  base_info.segment = -1;
  base_info.offset = Eigen::Isometry3d::Identity();
  fill_inertial(*path.front(), base_info);
  m.links_.push_back(base_info);

  Eigen::Isometry3d acc = Eigen::Isometry3d::Identity();  // last moving segment's tip -> current link
  for (std::size_t k = 1; k < path.size(); ++k) {
    const urdf::Link& child = *path[k];
    const urdf::Joint& joint = *child.parent_joint;
    const Eigen::Isometry3d origin = to_isometry(joint.parent_to_joint_origin_transform);
    LinkInfo info;
    info.name = child.name;
    fill_inertial(child, info);
    if (joint.type == urdf::Joint::FIXED) {
      acc = acc * origin;
      info.segment = static_cast<int>(m.segments_.size()) - 1;
      info.offset = acc;
      m.links_.push_back(info);
      continue;
    }
    JointInfo j;
    j.name = joint.name;
    j.effort = joint.limits ? joint.limits->effort : 0.0;
    j.velocity = joint.limits ? joint.limits->velocity : 0.0;
    if (!(std::isfinite(j.effort) && j.effort >= 0) || !(std::isfinite(j.velocity) && j.velocity >= 0))
      throw InputError("joint '" + joint.name + "' <limit>: effort and velocity must be finite and >= 0, got " +
                       number_text(j.effort) + " and " + number_text(j.velocity));
    switch (joint.type) {
      case urdf::Joint::REVOLUTE:
        j.type = JointType::Revolute;
        break;
      case urdf::Joint::CONTINUOUS:
        j.type = JointType::Continuous;
        break;
      case urdf::Joint::PRISMATIC:
        j.type = JointType::Prismatic;
        break;
      default:
        throw InputError("joint '" + joint.name + "' has a type (floating or planar) that a serial chain cannot hold");
    }
    if (j.type == JointType::Continuous) {
      j.lower = -std::numeric_limits<double>::infinity();
      j.upper = std::numeric_limits<double>::infinity();
    } else {
      if (!joint.limits) throw InputError("joint '" + joint.name + "' has no <limit>");
      j.lower = joint.limits->lower;
      j.upper = joint.limits->upper;
      if (!std::isfinite(j.lower) || !std::isfinite(j.upper))
        throw InputError("joint '" + joint.name + "' has a non-finite limit");
      if (j.lower > j.upper)
        throw InputError("joint '" + joint.name + "' has lower limit > upper limit");
    }
    Eigen::Vector3d axis(joint.axis.x, joint.axis.y, joint.axis.z);
    if (!(axis.norm() > 1e-12)) throw InputError("joint '" + joint.name + "' has a zero axis");
    axis.normalize();
    SegmentGeometry seg;
    seg.link = child.name;
    seg.pre = acc * origin;
    seg.axis = axis;
    seg.post = Eigen::Isometry3d::Identity();
    seg.prismatic = j.type == JointType::Prismatic;
    m.segments_.push_back(seg);
    m.joints_.push_back(j);
    info.segment = static_cast<int>(m.segments_.size()) - 1;
    info.offset = Eigen::Isometry3d::Identity();
    m.links_.push_back(info);
    acc = Eigen::Isometry3d::Identity();
  }
  if (m.segments_.empty())
    throw InputError("the chain from '" + base + "' to '" + tip + "' has no moving joint");

  // Fold trailing fixed joints into the last segment so that its tip frame is the chain's tip.
  if (!acc.isApprox(Eigen::Isometry3d::Identity(), 0.0)) {
    const int last = static_cast<int>(m.segments_.size()) - 1;
    m.segments_.back().post = acc;
    const Eigen::Isometry3d inv = acc.inverse();
    for (auto& l : m.links_)
      if (l.segment == last) l.offset = inv * l.offset;
  }

  const int n = static_cast<int>(m.joints_.size());
  m.lower_.resize(n);
  m.upper_.resize(n);
  std::ostringstream canon;
  canon.precision(17);
  double reach = 0.0;
  Eigen::Isometry3d frame = Eigen::Isometry3d::Identity();
  Eigen::Vector3d previous = Eigen::Vector3d::Zero();
  for (int i = 0; i < n; ++i) {
    const SegmentGeometry& s = m.segments_[i];
    const JointInfo& j = m.joints_[i];
    m.lower_[i] = j.lower;
    m.upper_[i] = j.upper;
    const Eigen::Isometry3d joint_frame = frame * s.pre;
    reach += (joint_frame.translation() - previous).norm();
    if (s.prismatic) reach += std::max(std::abs(j.lower), std::abs(j.upper));
    previous = joint_frame.translation();
    frame = joint_frame * s.post;
    const KDL::Joint kdl_joint(j.name, to_kdl(s.pre.translation()), to_kdl(s.pre.linear() * s.axis),
                               s.prismatic ? KDL::Joint::TransAxis : KDL::Joint::RotAxis);
    m.chain_.addSegment(KDL::Segment(s.link, kdl_joint, to_kdl(s.pre * s.post)));
    canon << static_cast<int>(j.type) << ' ' << j.lower << ' ' << j.upper << ' ';
    append(canon, s.pre);
    canon << s.axis.transpose() << ' ';
    append(canon, s.post);
  }
  reach += (frame.translation() - previous).norm();
  m.reach_ = reach;
  m.hash_ = digest(canon.str());  // unchanged text: the shipped maps record this value

  // The bodies: what the dynamics and the collision checks use, and the maps do not.
  std::ostringstream bodies;
  bodies.precision(17);
  m.total_mass_ = 0.0;
  for (const LinkInfo& l : m.links_) {
    m.total_mass_ += l.mass;
    bodies << l.mass << ' ' << l.com.transpose() << ' ';
    for (int r = 0; r < 3; ++r)
      for (int c = r; c < 3; ++c) bodies << l.inertia(r, c) << ' ';
    for (const CollisionElement& e : l.collisions) {
      bodies << static_cast<int>(e.kind) << ' ' << e.size.transpose() << ' ' << e.filename << ' ';
      append(bodies, e.origin);
    }
  }
  m.body_hash_ = digest(bodies.str());
  return m;
}

std::vector<std::string> ChainModel::joint_names() const {
  std::vector<std::string> names;
  names.reserve(joints_.size());
  for (const auto& j : joints_) names.push_back(j.name);
  return names;
}

int ChainModel::link_index(const std::string& name) const {
  for (std::size_t i = 0; i < links_.size(); ++i)
    if (links_[i].name == name) return static_cast<int>(i);
  throw InputError("link '" + name + "' is not on the chain from '" + base_ + "' to '" + tip_ + "'");
}

void ChainModel::check_configuration(const Eigen::Ref<const Eigen::VectorXd>& q, const char* what) const {
  if (q.size() != n_joints())
    throw InputError(std::string(what) + " has " + std::to_string(q.size()) + " entries; the chain has " +
                     std::to_string(n_joints()) + " joints");
  for (int i = 0; i < q.size(); ++i)
    if (!std::isfinite(q[i]))
      throw InputError(std::string(what) + "[" + std::to_string(i) + "] is not finite (NaN or inf)");
}

}  // namespace snakehead
