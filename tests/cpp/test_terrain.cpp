// The terrain query against closed forms (a plane, a heightfield of one plane, a pyramid mesh), brute force over
// every triangle, the tree against brute force on a random surface, threads, and bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <thread>
#include <vector>

#include "snakehead/limits.hpp"
#include "snakehead/model.hpp"
#include "snakehead/terrain.hpp"

namespace {

using snakehead::HeightfieldGrid;
using snakehead::InputError;
using snakehead::Terrain;
using Vertices = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A heightfield of nx x ny heights of z = f(x, y) over [x0, x0 + sx] x [y0, y0 + sy].
template <class F>
Terrain grid_of(long nx, long ny, double sx, double sy, const Eigen::Vector3d& origin, F f) {
  HeightfieldGrid g;
  g.nx = nx;
  g.ny = ny;
  g.size_x = sx;
  g.size_y = sy;
  g.origin = origin;
  for (long i = 0; i < nx; ++i)
    for (long j = 0; j < ny; ++j)
      g.heights.push_back(f(origin.x() + sx * static_cast<double>(i) / static_cast<double>(nx - 1),
                            origin.y() + sy * static_cast<double>(j) / static_cast<double>(ny - 1)));
  return Terrain::heightfield(std::move(g));
}

double one_height(const Terrain& t, double x, double y) {
  const double xy[2] = {x, y};
  double out = 0.0;
  t.height(xy, 1, &out);
  return out;
}

double one_distance(const Terrain& t, const Eigen::Vector3d& p) {
  double out = 0.0;
  t.signed_distance(p.data(), 1, &out);
  return out;
}

// Brute force: the unsigned distance from p to every triangle (sampled densely on each).
double brute_distance(const Terrain& t, const Eigen::Vector3d& p) {
  double best = std::numeric_limits<double>::infinity();
  const auto& v = t.vertices();
  for (const auto& f : t.faces()) {
    const Eigen::Vector3d a = v.row(f[0]), b = v.row(f[1]), c = v.row(f[2]);
    constexpr int kSteps = 60;
    for (int i = 0; i <= kSteps; ++i)
      for (int j = 0; i + j <= kSteps; ++j) {
        const double u = i / double(kSteps), w = j / double(kSteps);
        best = std::min(best, (a + u * (b - a) + w * (c - a) - p).norm());
      }
  }
  return best;
}

TEST(Terrain, PlaneMatchesItsClosedForm) {
  const Eigen::Vector3d n = Eigen::Vector3d(0.1, -0.2, 1.0).normalized(), p(0.3, 0.4, 0.5);
  const Terrain t = Terrain::plane(Eigen::Vector3d(0.1, -0.2, 1.0) * 3.0, p);
  EXPECT_NEAR(one_height(t, 1.0, 2.0), 0.5 - (0.1 * 0.7 - 0.2 * 1.6) / 1.0, 1e-12);
  const Eigen::Vector3d q(1.0, -2.0, 3.0);
  EXPECT_NEAR(one_distance(t, q), n.dot(q - p), 1e-12);
  double m[3];
  const double xy[2] = {5.0, 5.0};
  t.normal(xy, 1, m);
  EXPECT_NEAR(Eigen::Map<Eigen::Vector3d>(m).dot(n), 1.0, 1e-12);
}

TEST(Terrain, HeightfieldOfAPlaneIsThatPlane) {
  const auto f = [](double x, double y) { return 0.2 * x - 0.1 * y + 0.05; };
  const Terrain t = grid_of(7, 5, 2.0, 1.0, {-1.0, -0.5, 0.3}, f);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> ux(-1.0, 1.0), uy(-0.5, 0.5), uz(-1.0, 1.0);
  const Eigen::Vector3d n = Eigen::Vector3d(-0.2, 0.1, 1.0).normalized();
  for (int k = 0; k < 200; ++k) {
    const double x = ux(rng), y = uy(rng), z = uz(rng);
    const double h = 0.3 + f(x, y);
    EXPECT_NEAR(one_height(t, x, y), h, 1e-12);
    // Well inside, the closest point is on the plane: the distance is the plane's.
    if (std::abs(x) < 0.5 && std::abs(y) < 0.2 && std::abs(z - h) < 0.1)
      EXPECT_NEAR(one_distance(t, {x, y, z}), (z - h) * n.z(), 1e-12);
    double m[3];
    const double xy[2] = {x, y};
    t.normal(xy, 1, m);
    EXPECT_NEAR(Eigen::Map<Eigen::Vector3d>(m).dot(n), 1.0, 1e-12);
  }
  EXPECT_TRUE(std::isnan(one_height(t, 1.5, 0.0)));
}

TEST(Terrain, HeightfieldSplitsEachCellAlongItsDiagonal) {
  // One cell, a single raised corner at (1, 1): below the diagonal (u >= v) the triangle (0,0) (1,0) (1,1).
  HeightfieldGrid g{2, 2, {0.0, 0.0, 0.0, 1.0}, 1.0, 1.0, Eigen::Vector3d::Zero()};
  const Terrain t = Terrain::heightfield(g);
  EXPECT_NEAR(one_height(t, 0.75, 0.25), 0.25, 1e-15);  // z = v
  EXPECT_NEAR(one_height(t, 0.25, 0.75), 0.25, 1e-15);  // z = u
  EXPECT_NEAR(one_height(t, 0.5, 0.5), 0.5, 1e-15);
}

TEST(Terrain, MeshHeightIsTheHighestSurfaceOnTheLine) {
  // Two horizontal squares at z = 0 and z = 1, the upper one half as wide.
  Vertices v(8, 3);
  v << -1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0, -0.5, -0.5, 1, 0.5, -0.5, 1, 0.5, 0.5, 1, -0.5, 0.5, 1;
  const Terrain t = Terrain::mesh(v, {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}, {4, 6, 7}});
  EXPECT_EQ(one_height(t, 0.0, 0.0), 1.0);
  EXPECT_EQ(one_height(t, 0.9, 0.0), 0.0);
  EXPECT_TRUE(std::isnan(one_height(t, 2.0, 0.0)));
  EXPECT_NEAR(one_distance(t, {0.0, 0.0, 1.5}), 0.5, 1e-15);
  EXPECT_NEAR(one_distance(t, {0.9, 0.0, 0.3}), 0.3, 1e-15);
  EXPECT_NEAR(one_distance(t, {0.9, 0.0, -0.3}), -0.3, 1e-15);
  EXPECT_NEAR(one_distance(t, {2.0, 0.0, 0.0}), 1.0, 1e-15);  // to the edge x = 1
}

TEST(Terrain, TreeEqualsBruteForceOnARoughHeightfield) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> bump(-0.05, 0.05);
  const Terrain t = grid_of(9, 8, 1.0, 1.0, {0.0, 0.0, 0.0}, [&](double, double) { return bump(rng); });
  std::uniform_real_distribution<double> u(-0.3, 1.3), w(-0.2, 0.2);
  for (int k = 0; k < 60; ++k) {
    const Eigen::Vector3d p(u(rng), u(rng), w(rng));
    const double d = one_distance(t, p);
    EXPECT_NEAR(std::abs(d), brute_distance(t, p), 2e-3) << p.transpose();  // brute force is sampled
    EXPECT_LE(std::abs(d), brute_distance(t, p) + 1e-12);
    const double h = one_height(t, p.x(), p.y());
    if (std::isfinite(h)) EXPECT_EQ(d >= 0.0, p.z() >= h);
  }
}

TEST(Terrain, MeshSignsByPseudonormalsAtEdgesAndVertices) {
  // A closed tetrahedron, faces counter-clockwise from outside: outside is positive, inside negative.
  Vertices v(4, 3);
  v << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  const Terrain t = Terrain::mesh(v, {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}});
  EXPECT_NEAR(one_distance(t, {0.1, 0.1, 0.1}), -0.1, 1e-15);
  EXPECT_NEAR(one_distance(t, {-0.1, -0.1, -0.1}), std::sqrt(0.03), 1e-15);  // nearest: the vertex at 0
  EXPECT_NEAR(one_distance(t, {0.5, -0.1, -0.1}), std::sqrt(0.02), 1e-15);   // nearest: the edge 0-1
}

TEST(Terrain, RepeatedVerticesAreOne) {
  // The tetrahedron as an STL file holds it: three vertices per triangle. Signs as with shared vertices.
  const std::array<std::array<int, 3>, 4> shared = {{{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}}};
  Eigen::Matrix<double, 4, 3, Eigen::RowMajor> corners;
  corners << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  Vertices v(12, 3);
  std::vector<std::array<int, 3>> faces;
  for (int f = 0; f < 4; ++f) {
    for (int k = 0; k < 3; ++k) v.row(3 * f + k) = corners.row(shared[f][k]);
    faces.push_back({3 * f, 3 * f + 1, 3 * f + 2});
  }
  const Terrain t = Terrain::mesh(v, faces);
  EXPECT_NEAR(one_distance(t, {-0.1, -0.1, -0.1}), std::sqrt(0.03), 1e-15);
  EXPECT_NEAR(one_distance(t, {0.5, -0.1, -0.1}), std::sqrt(0.02), 1e-15);
  EXPECT_NEAR(one_distance(t, {0.5, 0.01, 0.01}), -0.01, 1e-15);
}

TEST(Terrain, CapsulesAndSpheres) {
  const Terrain flat = Terrain::plane({0, 0, 1}, {0, 0, 0});
  const Terrain grid = grid_of(3, 3, 2.0, 2.0, {-1.0, -1.0, 0.0}, [](double, double) { return 0.0; });
  const double a[6] = {0.0, 0.0, 0.5, 0.2, 0.1, -0.2}, b[6] = {0.5, 0.0, 0.2, 0.3, 0.3, 0.4}, r[2] = {0.1, 0.05};
  for (const Terrain* t : {&flat, &grid}) {
    double out[2];
    t->capsule_clearance(a, b, r, 2, out);
    EXPECT_NEAR(out[0], 0.2 - 0.1, 1e-12);
    EXPECT_NEAR(out[1], -0.2 - 0.05, 1e-12);
    t->sphere_clearance(a, r, 2, out);
    EXPECT_NEAR(out[0], 0.5 - 0.1, 1e-12);
  }
  // A segment through a triangle: its lower end's signed distance.
  Vertices v(3, 3);
  v << -1, -1, 0, 1, -1, 0, 0, 1, 0;
  const Terrain tri = Terrain::mesh(v, {{0, 1, 2}});
  const double p[3] = {0.0, 0.0, 1.0}, q[3] = {0.0, 0.0, -1.0}, rr[1] = {0.01};
  double out;
  tri.capsule_clearance(p, q, rr, 1, &out);
  EXPECT_NEAR(out, -1.01, 1e-12);  // the lower end is 1 below
  const double p2[3] = {2.0, 0.0, 0.5}, q2[3] = {2.0, 0.0, -0.5};
  tri.capsule_clearance(p2, q2, rr, 1, &out);
  // Beside the triangle, its lower end below the triangle's plane: signed by that end's nearest point, (0.8, -0.6, 0)
  // on the edge (1, -1, 0) - (0, 1, 0).
  EXPECT_NEAR(out, -std::sqrt(1.2 * 1.2 + 0.6 * 0.6 + 0.25) - 0.01, 1e-12);
}

TEST(Terrain, ThreadsGiveTheSameAnswers) {
  const Terrain t = grid_of(64, 64, 4.0, 4.0, {-2.0, -2.0, 0.0}, [](double x, double y) {
    return 0.1 * std::sin(3.0 * x) * std::cos(2.0 * y);
  });
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-2.5, 2.5);
  std::vector<double> points(3 * 5000);
  for (double& x : points) x = u(rng) * 0.5;
  std::vector<double> expected(5000);
  t.signed_distance(points.data(), 5000, expected.data());
  std::vector<std::thread> threads;
  std::vector<std::vector<double>> got(4, std::vector<double>(5000));
  for (int k = 0; k < 4; ++k) threads.emplace_back([&, k] { t.signed_distance(points.data(), 5000, got[k].data()); });
  for (auto& th : threads) th.join();
  for (const auto& g : got) EXPECT_EQ(g, expected);
}

TEST(Terrain, BadInputIsAnInputError) {
  EXPECT_THROW(Terrain::plane({0, 0, 0}, {0, 0, 0}), InputError);
  EXPECT_THROW(Terrain::plane({1, 0, 0}, {0, 0, 0}), InputError);
  EXPECT_THROW(Terrain::plane({0, 0, 1}, {kNaN, 0, 0}), InputError);
  EXPECT_THROW(Terrain::heightfield(HeightfieldGrid{1, 2, {0, 0}, 1, 1, Eigen::Vector3d::Zero()}), InputError);
  EXPECT_THROW(Terrain::heightfield(HeightfieldGrid{2, 2, {0, 0, kNaN, 0}, 1, 1, Eigen::Vector3d::Zero()}), InputError);
  EXPECT_THROW(Terrain::heightfield(HeightfieldGrid{2, 2, {0, 0, 0, 0}, 0, 1, Eigen::Vector3d::Zero()}), InputError);
  EXPECT_THROW(Terrain::heightfield(HeightfieldGrid{2, 2, {0, 0, 0}, 1, 1, Eigen::Vector3d::Zero()}), InputError);
  EXPECT_THROW(Terrain::heightfield(HeightfieldGrid{snakehead::limits::kMaxTerrainCells + 2, 2, {}, 1, 1,
                                                    Eigen::Vector3d::Zero()}),
               InputError);
  Vertices v(3, 3);
  v << 0, 0, 0, 1, 0, 0, 2, 0, 0;
  EXPECT_THROW(Terrain::mesh(v, {}), InputError);
  EXPECT_THROW(Terrain::mesh(v, {{0, 1, 3}}), InputError);
  EXPECT_THROW(Terrain::mesh(v, {{0, 1, 2}}), InputError);  // no area
}

}  // namespace
