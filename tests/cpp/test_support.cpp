// Support polygons: the convex hull and the signed margin of a point, against closed forms.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

#include "snakehead/support.hpp"

namespace {

using Points = Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>;

Points square_with_inside_and_edge_points() {
  Points p(7, 2);
  p << 0, 0, 2, 0, 2, 2, 0, 2,  // the square's corners
      1, 1,                     // inside
      1, 0,                     // on an edge
      0.5, 1.5;                 // inside
  return p;
}

TEST(ConvexHull, SquareKeepsItsCornersCounterClockwise) {
  const Points p = square_with_inside_and_edge_points();
  const std::vector<int> h = snakehead::convex_hull(p);
  ASSERT_EQ(h.size(), 4u);
  double area2 = 0.0;  // twice the shoelace area: positive for counter-clockwise
  for (std::size_t i = 0; i < h.size(); ++i) {
    const auto& a = p.row(h[i]);
    const auto& b = p.row(h[(i + 1) % h.size()]);
    area2 += a(0) * b(1) - a(1) * b(0);
  }
  EXPECT_DOUBLE_EQ(area2, 8.0);
}

TEST(ConvexHull, DegenerateSets) {
  Points line(3, 2);
  line << 0, 0, 1, 1, 3, 3;
  EXPECT_EQ(snakehead::convex_hull(line).size(), 2u);
  Points same(2, 2);
  same << 1, 1, 1, 1;
  EXPECT_EQ(snakehead::convex_hull(same).size(), 1u);
  EXPECT_TRUE(snakehead::convex_hull(Points(0, 2)).empty());
}

TEST(ConvexHull, PointsApartByRoundOffKeepEveryCorner) {
  // the twin of (0.1, 0.1394) at x = 0.10000000000000003 sorts after (0.1, 0.44) and (0.1, 0.5638): the hull is the
  // triangle (-0.08, 0.43), (0.1, 0.1394), (0.1, 0.5638), not a segment
  Points p(5, 2);
  p << 0.10000000000000003, 0.1394, 0.1, 0.5638, 0.1, 0.44, 0.1, 0.1394, -0.08, 0.43;
  std::vector<int> h = snakehead::convex_hull(p);
  ASSERT_EQ(h.size(), 3u);
  EXPECT_NE(std::find(h.begin(), h.end(), 4), h.end());
  EXPECT_NE(std::find(h.begin(), h.end(), 1), h.end());
  const bool low = std::find(h.begin(), h.end(), 0) != h.end() || std::find(h.begin(), h.end(), 3) != h.end();
  EXPECT_TRUE(low);
  EXPECT_NEAR(snakehead::hull_margin(p, Eigen::Vector2d(0.0, 0.4)), 0.0, 0.1);  // inside: not a segment's -distance
  EXPECT_GT(snakehead::hull_margin(p, Eigen::Vector2d(0.05, 0.4)), 0.0);
}

TEST(HullMargin, InsideOutsideAndDegenerate) {
  const Points p = square_with_inside_and_edge_points();
  EXPECT_DOUBLE_EQ(snakehead::hull_margin(p, Eigen::Vector2d(1.0, 1.0)), 1.0);   // centre: 1 from each edge
  EXPECT_DOUBLE_EQ(snakehead::hull_margin(p, Eigen::Vector2d(0.5, 1.0)), 0.5);
  EXPECT_DOUBLE_EQ(snakehead::hull_margin(p, Eigen::Vector2d(3.0, 1.0)), -1.0);  // outside, beside an edge
  EXPECT_NEAR(snakehead::hull_margin(p, Eigen::Vector2d(3.0, 3.0)), -std::sqrt(2.0), 1e-15);  // off a corner
  Points seg(2, 2);
  seg << 0, 0, 2, 0;
  EXPECT_DOUBLE_EQ(snakehead::hull_margin(seg, Eigen::Vector2d(1.0, 0.5)), -0.5);  // a segment has no inside
  EXPECT_EQ(snakehead::hull_margin(Points(0, 2), Eigen::Vector2d(0, 0)), -std::numeric_limits<double>::infinity());
}

TEST(ConvexMargin, OnAHullEqualsHullMarginOfThePoints) {
  // random clouds (and degenerate ones: a segment, a point, none): the margin on the hull's vertices, built with
  // reused buffers, equals hull_margin of the whole cloud (which builds the hull itself), bit for bit
  std::srand(3);
  const auto uniform = [] { return 2.0 * std::rand() / RAND_MAX - 1.0; };
  snakehead::HullWork work;
  std::vector<int> hull;
  for (int trial = 0; trial < 200; ++trial) {
    const int n = trial % 9;
    Points p(n, 2);
    for (int i = 0; i < n; ++i) p.row(i) << uniform(), trial % 7 == 0 ? 0.5 * p(i, 0) : uniform();  // some collinear
    snakehead::convex_hull_into(p, work, hull);
    EXPECT_EQ(hull, snakehead::convex_hull(p));
    Points v(static_cast<Eigen::Index>(hull.size()), 2);
    for (std::size_t i = 0; i < hull.size(); ++i) v.row(static_cast<Eigen::Index>(i)) = p.row(hull[i]);
    for (int k = 0; k < 20; ++k) {
      const Eigen::Vector2d xy(1.5 * uniform(), 1.5 * uniform());
      const double margin = snakehead::convex_margin(v.data(), v.rows(), xy);
      EXPECT_EQ(margin, snakehead::hull_margin(p, xy));
      EXPECT_EQ(margin, snakehead::hull_margin(v, xy));  // the hull's hull is itself: zmp_check's old margins
    }
  }
  Points square(4, 2);
  square << 0, 0, 2, 0, 2, 2, 0, 2;  // counter-clockwise already: closed forms
  EXPECT_DOUBLE_EQ(snakehead::convex_margin(square.data(), 4, Eigen::Vector2d(1.0, 0.5)), 0.5);
  EXPECT_DOUBLE_EQ(snakehead::convex_margin(square.data(), 4, Eigen::Vector2d(3.0, 1.0)), -1.0);
}

TEST(HullMargins, ManySamplesWithActiveMasks) {
  const Points p = square_with_inside_and_edge_points();
  std::vector<double> pts;
  for (int s = 0; s < 2; ++s)
    for (int i = 0; i < 7; ++i) pts.insert(pts.end(), {p(i, 0), p(i, 1)});
  std::vector<unsigned char> active(14, 1);
  for (int i = 7; i < 14; ++i) active[i] = (i - 7 == 0 || i - 7 == 1) ? 1 : 0;  // sample 1: a segment
  const double xy[4] = {1.0, 1.0, 1.0, 0.5};
  const auto m = snakehead::hull_margins(pts.data(), active.data(), xy, 2, 7);
  EXPECT_DOUBLE_EQ(m[0], 1.0);
  EXPECT_DOUBLE_EQ(m[1], -0.5);
}

TEST(ConvexHulls, ManySamplesIndexTheirOwnPoints) {
  const Points p = square_with_inside_and_edge_points();
  std::vector<double> pts;
  for (int s = 0; s < 3; ++s)
    for (int i = 0; i < 7; ++i) pts.insert(pts.end(), {p(i, 0), p(i, 1)});
  std::vector<unsigned char> active(21, 1);
  for (int i = 0; i < 7; ++i) {
    active[7 + i] = (i == 2 || i == 4 || i == 6) ? 1 : 0;  // sample 1: a triangle of points 2, 4, 6
    active[14 + i] = 0;                                        // sample 2: nothing touches
  }
  std::vector<int> vertex(21), count(3);
  snakehead::convex_hulls(pts.data(), active.data(), 3, 7, vertex.data(), count.data());
  EXPECT_EQ(count[0], 4);
  EXPECT_EQ(count[1], 3);
  EXPECT_EQ(count[2], 0);
  const std::vector<int> h = snakehead::convex_hull(p);  // sample 0: the single hull's indices
  for (int k = 0; k < 4; ++k) EXPECT_EQ(vertex[k], h[static_cast<std::size_t>(k)]);
  EXPECT_EQ(vertex[4], -1);
  std::vector<int> tri(vertex.begin() + 7, vertex.begin() + 10);
  std::sort(tri.begin(), tri.end());
  EXPECT_EQ(tri, (std::vector<int>{2, 4, 6}));  // indices into the sample's own 7 points
  EXPECT_EQ(vertex[14], -1);
}

}  // namespace
