// The model and the fast kinematics against KDL's own recursive solvers, and bad input.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "snakehead/kinematics.hpp"
#include "snakehead/model.hpp"

using snakehead::ChainModel;
using snakehead::InputError;

namespace {

const std::string kUrdfDir = SNAKEHEAD_URDF_DIR;
const std::string kSnake = kUrdfDir + "/snake16.urdf";
const std::string kMixed = kUrdfDir + "/../tests/data/mixed_chain.urdf";

Eigen::VectorXd random_q(const ChainModel& m, std::mt19937& rng) {
  Eigen::VectorXd q(m.n_joints());
  for (int i = 0; i < m.n_joints(); ++i) {
    const double lo = std::isfinite(m.lower()[i]) ? m.lower()[i] : -M_PI;
    const double hi = std::isfinite(m.upper()[i]) ? m.upper()[i] : M_PI;
    q[i] = std::uniform_real_distribution<double>(lo, hi)(rng);
  }
  return q;
}

void expect_matches_kdl(const ChainModel& m, int samples) {
  std::mt19937 rng(42);
  snakehead::Jacobian jac;
  Eigen::Isometry3d tip;
  for (int k = 0; k < samples; ++k) {
    const Eigen::VectorXd q = random_q(m, rng);
    const Eigen::Isometry3d fk = snakehead::forward_kinematics(m, q);
    const Eigen::Isometry3d ref = snakehead::kdl_forward_kinematics(m, q);
    ASSERT_LT((fk.matrix() - ref.matrix()).cwiseAbs().maxCoeff(), 1e-10);
    snakehead::tip_jacobian(m, q, jac, tip);
    ASSERT_LT((tip.matrix() - ref.matrix()).cwiseAbs().maxCoeff(), 1e-10);
    ASSERT_LT((jac - snakehead::kdl_jacobian(m, q)).cwiseAbs().maxCoeff(), 1e-10);
    // The tip is the last of the link frames.
    snakehead::Frames frames;
    snakehead::link_frames(m, q, frames);
    ASSERT_LT((frames.back().matrix() - ref.matrix()).cwiseAbs().maxCoeff(), 1e-10);
  }
}

}  // namespace

TEST(Model, Snake16Structure) {
  const auto m = ChainModel::from_urdf_file(kSnake, "link_0", "head_tip");
  EXPECT_EQ(m.n_joints(), 16);
  EXPECT_EQ(m.links().size(), 20u);  // 17 links + 3 marker frames
  EXPECT_EQ(m.joint_names().front(), "joint_1");
  EXPECT_EQ(m.joint_names().back(), "joint_16");
  for (int i = 0; i < 16; ++i) {
    EXPECT_NEAR(m.lower()[i], -M_PI / 2, 1e-12);
    EXPECT_NEAR(m.upper()[i], M_PI / 2, 1e-12);
    // Odd joints (1-based) yaw about z, even joints pitch about y.
    const Eigen::Vector3d expected = (i % 2 == 0) ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitY();
    EXPECT_LT((m.segments()[i].axis - expected).norm(), 1e-12);
  }
  double mass = 0;
  for (const auto& l : m.links()) mass += l.mass;
  EXPECT_NEAR(mass, 3.2, 1e-9);
  EXPECT_NEAR(m.reach(), 1.384, 1e-12);  // base origin -> each joint -> tip, straight
}

TEST(Kinematics, Snake16StraightTipAt1384) {
  const auto m = ChainModel::from_urdf_file(kSnake, "link_0", "head_tip");
  const Eigen::Isometry3d tip = snakehead::forward_kinematics(m, Eigen::VectorXd::Zero(16));
  EXPECT_NEAR(tip.translation().x(), 1.384, 1e-12);
  EXPECT_NEAR(tip.translation().y(), 0.0, 1e-12);
  EXPECT_NEAR(tip.translation().z(), 0.0, 1e-12);
}

TEST(Kinematics, Snake16MatchesKdl) {
  expect_matches_kdl(ChainModel::from_urdf_file(kSnake, "link_0", "head_tip"), 1000);
  expect_matches_kdl(ChainModel::from_urdf_file(kSnake, "neck_end", "head_tip"), 1000);
  expect_matches_kdl(ChainModel::from_urdf_file(kSnake, "link_10", "head_tip"), 1000);
}

TEST(Kinematics, MixedJointsMatchKdl) {
  const auto m = ChainModel::from_urdf_file(kMixed, "world", "tool");
  EXPECT_EQ(m.n_joints(), 4);
  EXPECT_EQ(m.joints()[1].type, snakehead::JointType::Continuous);
  EXPECT_EQ(m.joints()[2].type, snakehead::JointType::Prismatic);
  EXPECT_FALSE(std::isfinite(m.lower()[1]));
  expect_matches_kdl(m, 1000);
}

TEST(Kinematics, WorldLinkFramesAreTheOriginTimesTheLinkFrames) {
  // the composed world frames (coordinate-axis joints turning two columns, identity rotations skipped) against the
  // plain product origin * link_frames, on the snake (yaw and pitch joints) and the mixed chain (other axes, a
  // prismatic joint); and a non-rigid origin (the general product)
  std::mt19937 rng(4);
  for (const auto& m : {ChainModel::from_urdf_file(kSnake, "link_0", "head_tip"),
                        ChainModel::from_urdf_file(kMixed, "world", "tool")}) {
    const long L = static_cast<long>(m.links().size());
    std::vector<double> out(static_cast<std::size_t>(16 * L));
    snakehead::Frames local, f;
    for (int trial = 0; trial < 200; ++trial) {
      const Eigen::VectorXd q = random_q(m, rng);
      Eigen::Isometry3d o = Eigen::Isometry3d::Identity();
      o.linear() = Eigen::AngleAxisd(0.3 * trial, Eigen::Vector3d(1.0, 2.0, 3.0).normalized()).toRotationMatrix();
      o.translation() = Eigen::Vector3d(0.1 * trial, -0.2, 0.05);
      Eigen::Matrix4d origin = o.matrix();
      if (trial % 10 == 9) origin(3, 0) = 0.5;  // not rigid
      snakehead::world_link_frames(m, origin, q, local, out.data());
      snakehead::link_frames(m, q, f);
      for (long k = 0; k < L; ++k) {
        const Eigen::Matrix4d want = origin * f[static_cast<std::size_t>(k)].matrix();
        const Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>> got(out.data() + 16 * k);
        EXPECT_LT((got - want).cwiseAbs().maxCoeff(), 1e-12) << "link " << k << " trial " << trial;
      }
    }
  }
}

TEST(Kinematics, FixedLinkFramesFollowTheirParent) {
  // bracket hangs from b by a fixed joint: its frame is b's frame times the fixed origin.
  const auto m = ChainModel::from_urdf_file(kMixed, "world", "tool");
  std::mt19937 rng(1);
  const Eigen::VectorXd q = random_q(m, rng);
  snakehead::Frames f;
  snakehead::link_frames(m, q, f);
  const int b = m.link_index("b"), bracket = m.link_index("bracket");
  Eigen::Isometry3d origin = Eigen::Isometry3d::Identity();
  origin.translation() = Eigen::Vector3d(0, 0.1, 0);
  origin.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitY()).toRotationMatrix();
  EXPECT_LT(((f[b] * origin).matrix() - f[bracket].matrix()).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_THROW(m.link_index("side"), InputError);  // a side branch is not on the chain
}

TEST(Model, BadInput) {
  EXPECT_THROW(ChainModel::from_urdf_file("/no/such/file.urdf", "a", "b"), InputError);
  EXPECT_THROW(ChainModel::from_urdf_string("<robot name='x'><link name='a'/>", "a", "b"), InputError);
  EXPECT_THROW(ChainModel::from_urdf_string("not xml at all", "a", "b"), InputError);
  EXPECT_THROW(ChainModel::from_urdf_file(kSnake, "link_0", "nope"), InputError);
  EXPECT_THROW(ChainModel::from_urdf_file(kSnake, "nope", "head_tip"), InputError);
  EXPECT_THROW(ChainModel::from_urdf_file(kSnake, "head_tip", "link_0"), InputError);  // not an ancestor
  EXPECT_THROW(ChainModel::from_urdf_file(kSnake, "link_3", "link_3"), InputError);
  EXPECT_THROW(ChainModel::from_urdf_file(kMixed, "d", "tool"), InputError);  // no moving joint
  const auto m = ChainModel::from_urdf_file(kSnake, "link_0", "head_tip");
  EXPECT_THROW(m.check_configuration(Eigen::VectorXd::Zero(15)), InputError);
  Eigen::VectorXd q = Eigen::VectorXd::Zero(16);
  q[3] = std::nan("");
  EXPECT_THROW(m.check_configuration(q), InputError);
}

TEST(Model, LowerAboveUpperIsRejected) {
  const std::string xml =
      "<robot name='r'><link name='a'/><link name='b'/>"
      "<joint name='j' type='revolute'><parent link='a'/><child link='b'/><axis xyz='0 0 1'/>"
      "<limit lower='1' upper='-1' effort='1' velocity='1'/></joint></robot>";
  try {
    ChainModel::from_urdf_string(xml, "a", "b");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("lower limit > upper limit"), std::string::npos);
  }
}

TEST(Model, HashDependsOnKinematicsOnly) {
  const auto a = ChainModel::from_urdf_file(kSnake, "neck_end", "head_tip");
  const auto b = ChainModel::from_urdf_file(kSnake, "neck_end", "head_tip");
  const auto c = ChainModel::from_urdf_file(kSnake, "link_10", "head_tip");
  EXPECT_EQ(a.hash(), b.hash());
  EXPECT_NE(a.hash(), c.hash());
  EXPECT_EQ(a.hash().size(), 16u);
}
