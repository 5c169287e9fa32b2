// The chain model: a serial chain between two named links of a URDF, immutable after construction.
//
// Like pinocchio's Model, it holds only what does not change from call to call (geometry, limits,
// inertias); every algorithm keeps its per-call state on the stack or in its own workspace, so one
// model may be shared by any number of threads.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <kdl/chain.hpp>

#include <stdexcept>
#include <string>
#include <vector>

namespace snakehead {

// Bad input from the caller (malformed URDF, unknown link, wrong size, NaN...). Derives from
// std::invalid_argument so that pybind11 turns it into a Python ValueError.
class InputError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

enum class JointType { Revolute, Continuous, Prismatic };

struct JointInfo {
  std::string name;
  JointType type;
  double lower;  // rad or m; -inf for continuous joints
  double upper;
  double effort;    // N m or N; 0 when the URDF gives none
  double velocity;  // rad/s or m/s; 0 when the URDF gives none
};

// One <collision> element of a link, as the URDF gives it.
enum class CollisionKind { Box, Cylinder, Sphere, Mesh };
struct CollisionElement {
  CollisionKind kind;
  Eigen::Isometry3d origin;  // the shape's frame in the link frame
  // Box: full extents; cylinder: (radius, length, 0), axis along the shape frame's z; sphere: (radius, 0, 0);
  // mesh: its scale.
  Eigen::Vector3d size;
  std::string filename;  // mesh only: the filename attribute as written (package://..., file://..., relative)
};

// One link on the path from base to tip (moving or attached by fixed joints), with its frame
// located relative to the chain: frame(link) = (tip frame of segment `segment`) * offset, where
// segment = -1 means the chain's base frame.
struct LinkInfo {
  std::string name;
  int segment;
  Eigen::Isometry3d offset;
  double mass;                // kg (0 for a link without <inertial>)
  Eigen::Vector3d com;        // m, in the link frame
  Eigen::Matrix3d inertia;    // kg m^2, about the com, axes of the link frame
  std::vector<CollisionElement> collisions;  // every <collision> element with a geometry, in file order
};

// Precomputed form of one moving segment for the fast kinematics path:
// T_segment(q) = pre * Motion(axis, q) * post.
struct SegmentGeometry {
  std::string link;  // the moving link this segment ends in
  Eigen::Isometry3d pre;
  Eigen::Vector3d axis;  // unit, in the joint frame
  Eigen::Isometry3d post;
  bool prismatic;
};

// The name of the root link of a URDF (an XML document or a file path, as ChainModel::from_urdf).
std::string urdf_root_link(const std::string& urdf);

class ChainModel {
 public:
  // `urdf` is either an XML document (its first non-blank character is '<') or a file path. The text is
  // checked (urdf_input.hpp) before urdfdom parses it; malformed numbers anywhere, and invalid inertial or
  // collision data of the chain's links (negative mass, an inertia that is not positive semidefinite, a box
  // of size <= 0), are InputErrors naming the link and the element.
  static ChainModel from_urdf(const std::string& urdf, const std::string& base, const std::string& tip);
  static ChainModel from_urdf_string(const std::string& xml, const std::string& base, const std::string& tip);
  static ChainModel from_urdf_file(const std::string& path, const std::string& base, const std::string& tip);

  int n_joints() const { return static_cast<int>(joints_.size()); }
  const std::string& base_name() const { return base_; }
  const std::string& tip_name() const { return tip_; }
  const std::vector<JointInfo>& joints() const { return joints_; }
  std::vector<std::string> joint_names() const;
  const Eigen::VectorXd& lower() const { return lower_; }
  const Eigen::VectorXd& upper() const { return upper_; }
  // Every link from base to tip inclusive, in chain order (fixed-joint links included).
  const std::vector<LinkInfo>& links() const { return links_; }
  int link_index(const std::string& name) const;  // throws InputError when not on the chain
  const std::vector<SegmentGeometry>& segments() const { return segments_; }
  // The equivalent KDL chain: one segment per moving joint, fixed joints folded in.
  const KDL::Chain& kdl_chain() const { return chain_; }
  // Sum of the distances between consecutive joint axes' origins and to the tip: the chain's reach bound (m).
  double reach() const { return reach_; }
  // A hex digest of everything kinematic (joint types, frames, axes, limits): two models with
  // the same hash have the same kinematics. Reachability maps record it (they depend on nothing else).
  const std::string& hash() const { return hash_; }
  // A hex digest of the links' bodies (masses, centres of mass, inertias, collision shapes): with hash(),
  // everything the model holds.
  const std::string& body_hash() const { return body_hash_; }
  // The sum of the link masses on the chain (kg). It may be 0 (a URDF without <inertial>): a caller that
  // needs a centre of mass must check for that.
  double total_mass() const { return total_mass_; }

  // Throws InputError unless q has n_joints finite entries.
  void check_configuration(const Eigen::Ref<const Eigen::VectorXd>& q, const char* what = "q") const;

 private:
  ChainModel() = default;
  std::string base_, tip_;
  std::vector<JointInfo> joints_;
  Eigen::VectorXd lower_, upper_;
  std::vector<LinkInfo> links_;
  std::vector<SegmentGeometry> segments_;
  KDL::Chain chain_;
  double reach_ = 0.0;
  double total_mass_ = 0.0;
  std::string hash_, body_hash_;
};

}  // namespace snakehead
