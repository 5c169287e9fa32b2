// The paper's boundary(P): the alpha shape chosen from MATLAB's shrink factor (alpha_shape.hpp),
// checked against brute-force computations on small clouds and known non-convex shapes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <set>

#include "snakehead/alpha_shape.hpp"
#include "snakehead/model.hpp"
#include "snakehead/workspace.hpp"

using namespace snakehead;

namespace {

// Points spread uniformly in a U: the box [0,3] x [0,1] x [0,3] without the notch [1,2] x [0,1] x [1,3].
std::vector<Eigen::Vector3d> u_shape(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> x(0, 3), y(0, 1), z(0, 3);
  std::vector<Eigen::Vector3d> p;
  while (static_cast<int>(p.size()) < n) {
    const Eigen::Vector3d q(x(rng), y(rng), z(rng));
    if (q.x() > 1 && q.x() < 2 && q.z() > 1) continue;
    p.push_back(q);
  }
  return p;
}

std::vector<Eigen::Vector3d> random_cloud(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g;
  std::vector<Eigen::Vector3d> p(n);
  for (auto& v : p) v = Eigen::Vector3d(g(rng), g(rng), 0.5 * g(rng));
  return p;
}

// Face-connected regions of the tetrahedra with circumradius <= alpha, by breadth-first search, and
// whether they cover every vertex of the triangulation: an independent count for the critical alpha.
std::pair<int, bool> regions_brute_force(const AlphaShape& s, double alpha) {
  const auto& tets = s.tetrahedra();
  const auto& r = s.circumradii();
  std::vector<int> label(tets.size(), -1);
  int regions = 0;
  for (std::size_t t = 0; t < tets.size(); ++t) {
    if (r[t] > alpha || label[t] >= 0) continue;
    std::vector<int> stack{static_cast<int>(t)};
    label[t] = regions;
    while (!stack.empty()) {
      const int a = stack.back();
      stack.pop_back();
      for (int b : s.neighbours()[a])
        if (b >= 0 && r[b] <= alpha && label[b] < 0) label[b] = regions, stack.push_back(b);
    }
    ++regions;
  }
  std::set<int> all, covered;
  for (std::size_t t = 0; t < tets.size(); ++t)
    for (int v : tets[t]) {
      all.insert(v);
      if (r[t] <= alpha) covered.insert(v);
    }
  return {regions, all == covered};
}

}  // namespace

TEST(AlphaShape, DelaunayTetrahedraHaveEmptyCircumspheresAndConsistentNeighbours) {
  const auto pts = random_cloud(150, 2);
  const AlphaShape s = AlphaShape::boundary(pts, 0.5);
  const auto& tets = s.tetrahedra();
  ASSERT_GT(tets.size(), 300u);
  double volume = 0.0;
  for (std::size_t t = 0; t < tets.size(); ++t) {
    const auto& v = tets[t];
    const Eigen::Vector3d a = pts[v[0]];
    Eigen::Matrix3d m;
    m << (pts[v[1]] - a).transpose(), (pts[v[2]] - a).transpose(), (pts[v[3]] - a).transpose();
    // The circumcentre c solves 2 (p_i - a) . (c - a) = |p_i - a|^2: an independent construction.
    const Eigen::Vector3d rhs(m.row(0).squaredNorm(), m.row(1).squaredNorm(), m.row(2).squaredNorm());
    const Eigen::Vector3d c = a + (2.0 * m).fullPivLu().solve(rhs);
    const double r = (c - a).norm();
    EXPECT_NEAR(s.circumradii()[t], r, 1e-9 * std::max(1.0, r));
    for (const auto& p : pts) EXPECT_GE((p - c).norm(), r - 1e-9) << "a point inside tetrahedron " << t << "'s sphere";
    volume += std::abs(m.determinant()) / 6.0;
    // Neighbours are mutual and share the three vertices other than the opposite one.
    for (int i = 0; i < 4; ++i) {
      const int u = s.neighbours()[t][i];
      if (u < 0) continue;
      const auto& w = tets[u];
      EXPECT_NE(std::find(s.neighbours()[u].begin(), s.neighbours()[u].end(), static_cast<int>(t)), s.neighbours()[u].end());
      for (int j = 0; j < 4; ++j)
        if (j != i) EXPECT_NE(std::find(w.begin(), w.end(), v[j]), w.end());
      EXPECT_EQ(std::find(w.begin(), w.end(), v[i]), w.end());
    }
  }
  // The tetrahedra tile the convex hull.
  EXPECT_NEAR(volume, ConvexHull::of(pts).volume, 1e-9 * volume);
}

TEST(AlphaShape, AlphaFromTheShrinkFactorAsMatlabChoosesIt) {
  const auto pts = random_cloud(120, 5);
  const AlphaShape s = AlphaShape::boundary(pts, 0.5);
  // The spectrum: distinct finite circumradii, ascending.
  std::vector<double> spectrum;
  for (double r : s.circumradii())
    if (std::isfinite(r)) spectrum.push_back(r);
  std::sort(spectrum.begin(), spectrum.end());
  spectrum.erase(std::unique(spectrum.begin(), spectrum.end()), spectrum.end());
  EXPECT_EQ(s.spectrum_size(), static_cast<std::int64_t>(spectrum.size()));
  // The critical alpha: the first spectrum value whose shape covers every vertex in one region.
  double critical = NAN;
  for (double a : spectrum) {
    const auto [regions, all] = regions_brute_force(s, a);
    if (regions == 1 && all) {
      critical = a;
      break;
    }
  }
  ASSERT_FALSE(std::isnan(critical));
  EXPECT_EQ(s.critical_alpha(), critical);
  // alpha = the ceil((1 - S) m)-th of the m spectrum values from the critical one up (at least the first).
  std::vector<double> from_critical;
  for (double a : spectrum)
    if (a >= critical) from_critical.push_back(a);
  const auto m = static_cast<double>(from_critical.size());
  for (double shrink : {0.0, 0.1, 0.5, 0.77, 1.0}) {
    const auto k = std::max(1, static_cast<int>(std::ceil((1 - shrink) * m)));
    EXPECT_EQ(s.alpha_for_shrink(shrink), from_critical[k - 1]) << "shrink " << shrink;
  }
  EXPECT_EQ(s.alpha(), s.alpha_for_shrink(0.5));
  // S = 1: the tightest single region holding every point; S = 0: the largest circumradius (the hull).
  const AlphaShape tight = AlphaShape::boundary(pts, 1.0);
  EXPECT_EQ(tight.alpha(), critical);
  EXPECT_EQ(tight.n_regions(), 1);
  EXPECT_EQ(AlphaShape::boundary(pts, 0.0).alpha(), spectrum.back());
  EXPECT_THROW(AlphaShape::boundary(pts, 1.5), InputError);
  EXPECT_THROW(AlphaShape::boundary(pts, -0.1), InputError);
  EXPECT_THROW(s.alpha_for_shrink(std::nan("")), InputError);
}

TEST(AlphaShape, BoundaryFollowsANonConvexCloud) {
  const auto pts = u_shape(6000, 3);
  const AlphaShape s = AlphaShape::boundary(pts, 0.5);
  EXPECT_EQ(s.n_regions(), 1);
  // Deep inside the arms and the bottom of the U: inside. In the notch, which no point comes near: outside.
  for (const Eigen::Vector3d p : {Eigen::Vector3d(0.5, 0.5, 2.0), Eigen::Vector3d(2.5, 0.5, 2.0),
                                  Eigen::Vector3d(1.5, 0.5, 0.5)})
    EXPECT_TRUE(s.contains(p)) << p.transpose();
  for (const Eigen::Vector3d p : {Eigen::Vector3d(1.5, 0.5, 2.0), Eigen::Vector3d(1.5, 0.5, 2.8)})
    EXPECT_FALSE(s.contains(p)) << p.transpose();
  // The convex hull fills the notch (the box: 9); the boundary holds most of the U (7), a little less
  // (between samples near the U's faces it cuts inside them).
  const ConvexHull hull = ConvexHull::of(pts);
  EXPECT_TRUE(hull.contains(Eigen::Vector3d(1.5, 0.5, 2.0)));
  EXPECT_NEAR(hull.volume, 9.0, 0.3);
  EXPECT_GT(s.volume(), 5.5);
  EXPECT_LT(s.volume(), 7.0);
  // Grid voxels inside: the same as testing every centre on its own.
  const VoxelGrid g = VoxelGrid::around(Eigen::Vector3d(1.5, 0.5, 1.5), 3.3, 0.3);
  const auto ids = s.voxels_inside(g);
  std::vector<std::int64_t> brute;
  for (std::int64_t k = 0; k < g.count(); ++k)
    if (s.contains(g.centre_of(k))) brute.push_back(k);
  EXPECT_EQ(ids, brute);
  EXPECT_GT(ids.size(), 150u);
}

TEST(AlphaShape, BadClouds) {
  std::vector<Eigen::Vector3d> flat;
  for (int k = 0; k < 50; ++k) flat.emplace_back(k % 7, k / 7, 0.0);
  EXPECT_THROW(AlphaShape::boundary(flat, 0.5), InputError);
  // A flat cloud reaches qhull, which fails: the error says why in one line, for both kinds of hull.
  for (int kind = 0; kind < 2; ++kind) {
    try {
      if (kind == 0) AlphaShape::boundary(flat, 0.5);
      else ConvexHull::of(flat);
      ADD_FAILURE() << "no error for a flat cloud";
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("spans no volume"), std::string::npos) << what;
      EXPECT_NE(what.find("(qhull: Q"), std::string::npos) << what;  // qhull's own message, e.g. "QH6154 ..."
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
  EXPECT_THROW(AlphaShape::boundary({Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX()}, 0.5), InputError);
  auto cloud = random_cloud(50, 1);
  cloud[3].x() = std::nan("");
  EXPECT_THROW(AlphaShape::boundary(cloud, 0.5), InputError);
}
