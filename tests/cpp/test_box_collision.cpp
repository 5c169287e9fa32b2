// Separating-axis box test against closed forms: face, vertex and edge-edge contacts, parallel edges, flat
// boxes, and the batch entry's indexing and input checks.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "snakehead/box_collision.hpp"
#include "snakehead/model.hpp"

namespace {

using snakehead::OrientedBox;

OrientedBox cube(const Eigen::Vector3d& centre, const Eigen::Matrix3d& rotation = Eigen::Matrix3d::Identity(),
                 double half = 0.5) {
  return OrientedBox{centre, rotation, Eigen::Vector3d::Constant(half)};
}

Eigen::Matrix3d about(const Eigen::Vector3d& axis, double angle) {
  return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
}

TEST(BoxBoxSat, AxisAlignedCubesApartAndOverlapping) {
  const OrientedBox a = cube(Eigen::Vector3d::Zero());
  EXPECT_NEAR(snakehead::box_box_sat(a, cube({1.3, 0.0, 0.0})), 0.3, 1e-15);  // faces 0.3 m apart
  EXPECT_NEAR(snakehead::box_box_sat(a, cube({0.9, 0.2, 0.0})), -0.1, 1e-15);  // 0.1 m deep along x
  EXPECT_NEAR(snakehead::box_box_sat(a, cube({0.0, 0.0, -1.0})), 0.0, 1e-15);  // touching faces
  // symmetric in its arguments
  EXPECT_NEAR(snakehead::box_box_sat(cube({1.3, 0.0, 0.0}), a), 0.3, 1e-15);
}

TEST(BoxBoxSat, CornerAgainstFace) {
  // b turned 45 deg about z, at x = 2: its corner points at a's face x = 0.5 from x = 2 - sqrt(2)/2
  const double d = 2.0;
  const double gap = snakehead::box_box_sat(cube(Eigen::Vector3d::Zero()),
                                            cube({d, 0.0, 0.0}, about(Eigen::Vector3d::UnitZ(), M_PI / 4)));
  EXPECT_NEAR(gap, d - std::sqrt(0.5) - 0.5, 1e-14);
}

TEST(BoxBoxSat, EdgeAgainstEdgeIsSeparatedByTheirCrossProduct) {
  // a turned 45 deg about x: its top edge runs along x at z = sqrt(2)/2; b turned 45 deg about y, above it:
  // its bottom edge runs along y at z = h - sqrt(2)/2. No face normal separates them as well as x cross y = z.
  const double h = 1.6;
  const OrientedBox a = cube(Eigen::Vector3d::Zero(), about(Eigen::Vector3d::UnitX(), M_PI / 4));
  const OrientedBox b = cube({0.0, 0.0, h}, about(Eigen::Vector3d::UnitY(), M_PI / 4));
  EXPECT_NEAR(snakehead::box_box_sat(a, b), h - std::sqrt(2.0), 1e-14);
  // the best face normal alone gives less: a's face normals are 45 deg from z
  const Eigen::Vector3d n = a.rotation.col(2);
  const double face = std::abs(n.dot(b.centre - a.centre)) - 0.5 - (b.rotation.transpose() * n).cwiseAbs().sum() * 0.5;
  EXPECT_LT(face, h - std::sqrt(2.0) - 0.1);
}

TEST(BoxBoxSat, ParallelEdgesGiveNoAxisAndStayFinite) {
  // Same orientation: the 3 cross products of parallel edges vanish and are skipped; the face normals decide.
  const Eigen::Matrix3d R = about(Eigen::Vector3d(1.0, 2.0, 3.0), 0.7);
  const OrientedBox a = cube(Eigen::Vector3d::Zero(), R);
  const OrientedBox b = cube(R * Eigen::Vector3d(1.25, 0.3, -0.2), R);
  const double gap = snakehead::box_box_sat(a, b);
  EXPECT_TRUE(std::isfinite(gap));
  EXPECT_NEAR(gap, 0.25, 1e-14);
}

TEST(BoxBoxSat, OverlappingParallelBoxesReportTheirDepth) {
  // Orientations equal only up to rounding (turned by +a then -a): the edge axes' lengths are rounding noise and
  // must be skipped, not divided into it (which reported ~0 m for boxes overlapping by decimetres).
  const Eigen::Vector3d half(0.15, 0.1, 0.05);
  for (double angle : {0.3, 1.1, 2.0, -2.7}) {
    const Eigen::Matrix3d R = about(Eigen::Vector3d(0.3, -1.0, 0.5), angle);
    const Eigen::Matrix3d R_again = R * about(Eigen::Vector3d::UnitZ(), angle) * about(Eigen::Vector3d::UnitZ(), -angle);
    const OrientedBox a{Eigen::Vector3d(0.1, 0.2, 0.3), R, half};
    const OrientedBox b{a.centre, R_again, half};
    EXPECT_NEAR(snakehead::box_box_sat(a, b), -2 * half.minCoeff(), 1e-12) << angle;
  }
}

TEST(BoxBoxSat, FlatAndPointBoxes) {
  // a zero-size box is a point: its gap to a cube along the face normal
  OrientedBox point = cube({0.0, 0.0, 0.8});
  point.half_extents.setZero();
  EXPECT_NEAR(snakehead::box_box_sat(point, cube(Eigen::Vector3d::Zero())), 0.3, 1e-15);
  // a square plate (zero thickness) lying inside a cube overlaps it by the cube's half extent plus the offset
  OrientedBox plate = cube({0.0, 0.0, 0.1});
  plate.half_extents.z() = 0.0;
  EXPECT_NEAR(snakehead::box_box_sat(plate, cube(Eigen::Vector3d::Zero())), -0.4, 1e-15);
}

TEST(BoxPairGaps, IndexesSamplesAndPairs) {
  // k = 3 cubes along x at T = 2 samples; the second sample moves box 2 away by 1 m
  const long T = 2, k = 3, P = 3;
  std::vector<double> centres(T * k * 3, 0.0), rotations(T * k * 9, 0.0), half(k * 3, 0.5);
  for (long t = 0; t < T; ++t)
    for (long b = 0; b < k; ++b) {
      centres[3 * (t * k + b)] = 1.5 * b + (t == 1 && b == 2 ? 1.0 : 0.0);
      for (int d = 0; d < 3; ++d) rotations[9 * (t * k + b) + 4 * d] = 1.0;
    }
  const std::vector<long> pairs = {0, 1, 0, 2, 2, 1};
  std::vector<double> gaps(T * P);
  snakehead::box_pair_gaps(centres.data(), rotations.data(), half.data(), pairs.data(), T, k, P, gaps.data());
  const std::vector<double> expected = {0.5, 2.0, 0.5, 0.5, 3.0, 1.5};
  for (long i = 0; i < T * P; ++i) EXPECT_NEAR(gaps[i], expected[i], 1e-15) << i;
}

TEST(BoxPairGaps, MinimumPerSampleStopsEarlyWithTheSameNumbers) {
  // 6 cubes of varied sizes scattered at 4 samples, all 15 pairs: the per-sample minimum equals the smallest
  // of all gaps exactly.
  const long T = 4, k = 6;
  std::vector<long> pairs;
  for (long a = 0; a < k; ++a)
    for (long b = a + 1; b < k; ++b) pairs.insert(pairs.end(), {b, a});
  const long P = static_cast<long>(pairs.size()) / 2;
  std::vector<double> centres(T * k * 3), rotations(T * k * 9), half(k * 3);
  for (long i = 0; i < k * 3; ++i) half[i] = 0.02 + 0.01 * static_cast<double>(i % 5);
  for (long tb = 0; tb < T * k; ++tb) {
    const double s = static_cast<double>(tb);
    centres[3 * tb] = 0.5 * std::sin(1.3 * s);
    centres[3 * tb + 1] = 0.5 * std::cos(2.1 * s);
    centres[3 * tb + 2] = 0.1 * std::sin(0.7 * s);
    const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> R = about(Eigen::Vector3d(1.0, s, 2.0 - s), 0.4 * s);
    std::copy(R.data(), R.data() + 9, rotations.begin() + 9 * tb);
  }
  std::vector<double> gaps(T * P), min_gaps(T);
  snakehead::box_pair_gaps(centres.data(), rotations.data(), half.data(), pairs.data(), T, k, P, gaps.data());
  snakehead::box_pair_min_gaps(centres.data(), rotations.data(), half.data(), pairs.data(), T, k, P, min_gaps.data());
  int overlapping = 0;
  for (long t = 0; t < T; ++t) {
    const double smallest = *std::min_element(gaps.begin() + t * P, gaps.begin() + (t + 1) * P);
    EXPECT_EQ(min_gaps[t], smallest) << t;
    overlapping += smallest <= 0.0;
  }
  EXPECT_GT(overlapping, 0);
  EXPECT_LT(overlapping, T);
  // no pairs: nothing can meet
  snakehead::box_pair_min_gaps(centres.data(), rotations.data(), half.data(), pairs.data(), T, k, 0, min_gaps.data());
  for (long t = 0; t < T; ++t) EXPECT_EQ(min_gaps[t], std::numeric_limits<double>::infinity());
}

TEST(BoxPairGaps, RejectsBadInput) {
  std::vector<double> centres(3, 0.0), rotations = {1, 0, 0, 0, 1, 0, 0, 0, 1}, half(3, 0.5), gaps(1);
  const std::vector<long> outside = {0, 1};
  EXPECT_THROW(snakehead::box_pair_gaps(centres.data(), rotations.data(), half.data(), outside.data(), 1, 1, 1,
                                        gaps.data()),
               snakehead::InputError);
  const std::vector<long> self = {0, 0};
  half[1] = -0.1;
  EXPECT_THROW(snakehead::box_pair_gaps(centres.data(), rotations.data(), half.data(), self.data(), 1, 1, 1,
                                        gaps.data()),
               snakehead::InputError);
  half[1] = 0.5;
  centres[2] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(snakehead::box_pair_gaps(centres.data(), rotations.data(), half.data(), self.data(), 1, 1, 1,
                                        gaps.data()),
               snakehead::InputError);
}

}  // namespace
