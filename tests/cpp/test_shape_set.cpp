// The convex-shape kernel against closed forms and brute force: signed distances of every kind of pair (apart and
// penetrating), convex hulls equal to the primitives they enclose, lowest points, the pruned minimum, threads,
// and bad input.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <thread>
#include <vector>

#include "snakehead/model.hpp"
#include "snakehead/shape_set.hpp"

namespace {

using snakehead::ConvexShape;
using snakehead::ShapeKind;
using snakehead::ShapeSet;

ConvexShape box(const Eigen::Vector3d& extents, int frame = 0) {
  return ConvexShape{ShapeKind::Box, frame, Eigen::Isometry3d::Identity(), extents, {}};
}
ConvexShape cylinder(double r, double length, int frame = 0) {
  return ConvexShape{ShapeKind::Cylinder, frame, Eigen::Isometry3d::Identity(), {r, length, 0.0}, {}};
}
ConvexShape sphere(double r, int frame = 0) {
  return ConvexShape{ShapeKind::Sphere, frame, Eigen::Isometry3d::Identity(), {r, 0.0, 0.0}, {}};
}
ConvexShape convex(const Eigen::Matrix3Xd& vertices, int frame = 0) {
  return ConvexShape{ShapeKind::Convex, frame, Eigen::Isometry3d::Identity(), Eigen::Vector3d::Zero(), vertices};
}
// The 8 corners of a box of these full extents, and its centre (an interior point qhull must drop).
Eigen::Matrix3Xd cube_vertices(const Eigen::Vector3d& extents) {
  Eigen::Matrix3Xd v(3, 9);
  for (int c = 0; c < 8; ++c)
    for (int d = 0; d < 3; ++d) v(d, c) = ((c >> d) & 1 ? 0.5 : -0.5) * extents(d);
  v.col(8).setZero();
  return v;
}

Eigen::Isometry3d pose(const Eigen::Vector3d& t, const Eigen::Matrix3d& R = Eigen::Matrix3d::Identity()) {
  Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
  p.linear() = R;
  p.translation() = t;
  return p;
}

Eigen::Isometry3d random_pose(std::mt19937& rng, double spread) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Eigen::Quaterniond q(u(rng), u(rng), u(rng), u(rng));
  return pose(spread * Eigen::Vector3d(u(rng), u(rng), u(rng)), q.normalized().toRotationMatrix());
}

double distance(const ConvexShape& a, const Eigen::Isometry3d& pa, const ConvexShape& b, const Eigen::Isometry3d& pb) {
  const ShapeSet sa({a}), sb({b});
  return snakehead::shape_signed_distance(sa, 0, pa, sb, 0, pb);
}

// Signed distance of a point to a box of half extents h at the origin (exact).
double point_box(const Eigen::Vector3d& p, const Eigen::Vector3d& h) {
  const Eigen::Vector3d q = p.cwiseAbs() - h;
  return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
}

// Minimum of a convex function over [0, 1] by ternary search.
double ternary_min(const std::function<double(double)>& f) {
  double lo = 0.0, hi = 1.0;
  for (int i = 0; i < 60; ++i) {
    const double m1 = lo + (hi - lo) / 3, m2 = hi - (hi - lo) / 3;
    if (f(m1) < f(m2))
      hi = m2;
    else
      lo = m1;
  }
  return f(0.5 * (lo + hi));
}

// Brute-force distance of two separate boxes: over each face of a, the distance of its points to b is convex,
// so nested ternary searches find its least value.
double brute_box_box(const Eigen::Vector3d& ha, const Eigen::Isometry3d& pa, const Eigen::Vector3d& hb,
                     const Eigen::Isometry3d& pb) {
  double best = std::numeric_limits<double>::infinity();
  const Eigen::Isometry3d a_in_b = pb.inverse() * pa;
  for (int axis = 0; axis < 3; ++axis)
    for (double side : {-1.0, 1.0}) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      const auto at = [&](double s, double r) {
        Eigen::Vector3d p;
        p(axis) = side * ha(axis);
        p(u) = (2 * s - 1) * ha(u);
        p(v) = (2 * r - 1) * ha(v);
        return point_box(a_in_b * p, hb);
      };
      best = std::min(best, ternary_min([&](double s) { return ternary_min([&](double r) { return at(s, r); }); }));
    }
  return best;
}

TEST(ShapeSetDistance, SphereSphereApartAndPenetrating) {
  EXPECT_NEAR(distance(sphere(0.1), pose({0, 0, 0}), sphere(0.05), pose({0.3, 0.1, -0.2})),
              std::sqrt(0.14) - 0.15, 1e-9);
  EXPECT_NEAR(distance(sphere(0.1), pose({0, 0, 0}), sphere(0.05), pose({0.05, 0.1, 0})), std::sqrt(0.0125) - 0.15,
              1e-9);
  EXPECT_NEAR(distance(sphere(0.1), pose({0, 0, 0}), sphere(0.05), pose({0.0, 0.02, 0})), -0.13, 1e-9);
}

TEST(ShapeSetDistance, SphereBoxIsThePointToBoxDistance) {
  std::mt19937 rng(1);
  const Eigen::Vector3d extents(0.2, 0.1, 0.06);
  for (int n = 0; n < 300; ++n) {
    const Eigen::Isometry3d pb = random_pose(rng, 0.2), ps = random_pose(rng, 0.2);
    const double expected = point_box(pb.inverse() * ps.translation(), extents / 2) - 0.04;
    EXPECT_NEAR(distance(sphere(0.04), ps, box(extents), pb), expected, 1e-9) << n;
    EXPECT_NEAR(distance(box(extents), pb, sphere(0.04), ps), expected, 1e-9) << n;
  }
}

TEST(ShapeSetDistance, ParallelCylindersAreAxisDistanceLessRadii) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int n = 0; n < 200; ++n) {
    const Eigen::Isometry3d frame = random_pose(rng, 1.0);
    const Eigen::Vector2d offset(0.15 * u(rng), 0.15 * u(rng));
    const double d = offset.norm() - 0.05 - 0.03;
    if (d < -0.02) continue;  // deep overlaps of round shapes: EPA's polytope is coarse there (tested below)
    const Eigen::Isometry3d pb = frame * pose({offset.x(), offset.y(), 0.05 * u(rng)});
    // penetrations of round shapes through libccd's EPA: good to ~3e-5 m (its polytope is inscribed)
    EXPECT_NEAR(distance(cylinder(0.05, 0.4), frame, cylinder(0.03, 0.3), pb), d, d < 0.0 ? 5e-5 : 2e-6)
        << n;
  }
}

TEST(ShapeSetDistance, CrossedCylindersAreLineDistanceLessRadii) {
  std::mt19937 rng(3);
  const Eigen::Matrix3d along_x = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  for (double gap : {0.2, 0.1, 0.081, 0.07, 0.05}) {
    const Eigen::Isometry3d frame = random_pose(rng, 1.0);
    // a along z through the origin, b along x through (0.01, gap, 0.02): closest points (0, 0, 0.02), (0, gap,
    // 0.02), inside both cylinders' lengths
    const double d = distance(cylinder(0.05, 0.4), frame, cylinder(0.03, 0.3), frame * pose({0.01, gap, 0.02}, along_x));
    EXPECT_NEAR(d, gap - 0.08, gap < 0.08 ? 5e-5 : 2e-6) << gap;  // EPA in penetration
  }
}

TEST(ShapeSetDistance, BoxBoxApartMatchesBruteForce) {
  std::mt19937 rng(4);
  const Eigen::Vector3d ea(0.2, 0.1, 0.06), eb(0.08, 0.15, 0.05);
  int tried = 0;
  for (int n = 0; n < 60; ++n) {
    const Eigen::Isometry3d pa = random_pose(rng, 0.1), pb = random_pose(rng, 0.3);
    const double brute = brute_box_box(ea / 2, pa, eb / 2, pb);
    if (brute < 1e-3) continue;  // touching or overlapping: brute force measures apart boxes only
    ++tried;
    EXPECT_NEAR(distance(box(ea), pa, box(eb), pb), brute, 1e-7) << n;
  }
  EXPECT_GT(tried, 20);
}

TEST(ShapeSetDistance, PenetrationDepths) {
  // spheres: r1 + r2 - |c1 - c2|
  EXPECT_NEAR(distance(sphere(0.1), pose({0, 0, 0}), sphere(0.1), pose({0.05, 0.05, 0.05})),
              std::sqrt(3 * 0.0025) - 0.2, 1e-9);
  // boxes overlapping face to face: the least overlap, along x here
  EXPECT_NEAR(distance(box({1, 1, 1}), pose({0, 0, 0}), box({1, 1, 1}), pose({0.9, 0.2, 0.1})), -0.1, 1e-9);
  EXPECT_NEAR(distance(box({1, 1, 1}), pose({0, 0, 0}), box({0.4, 0.4, 0.4}), pose({0.1, 0.0, 0.6})), -0.1, 1e-9);
  // turned about the overlap's normal: still the same face overlap
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitX()).toRotationMatrix();
  EXPECT_NEAR(distance(box({1, 1, 1}), pose({0, 0, 0}), box({0.2, 0.2, 0.2}), pose({0.55, 0.0, 0.0}, R)),
              -(0.5 - (0.55 - 0.1)), 1e-9);
  // parallel cylinders side by side
  EXPECT_NEAR(distance(cylinder(0.05, 0.4), pose({0, 0, 0}), cylinder(0.03, 0.3), pose({0.07, 0, 0})), -0.01, 5e-5);
  // sphere into a box face, a cylinder's cap and a convex cube's face
  EXPECT_NEAR(distance(sphere(0.1), pose({0.55, 0, 0}), box({1, 1, 1}), pose({0, 0, 0})), -0.05, 1e-9);
  EXPECT_NEAR(distance(sphere(0.01), pose({0, 0, 0.195}), cylinder(0.05, 0.4), pose({0, 0, 0})), -0.015, 1e-9);
  EXPECT_NEAR(distance(sphere(0.1), pose({0.55, 0.1, 0}), convex(cube_vertices({1, 1, 1})), pose({0, 0, 0})), -0.05,
              1e-9);
  EXPECT_NEAR(distance(convex(cube_vertices({1, 1, 1})), pose({0, 0, 0}), sphere(0.1), pose({0.3, 0.1, 0})), -0.3,
              1e-9);
}

TEST(ShapeSetDistance, PenetrationDepthOfBoxesIsTheLeastOverlapOnRandomPoses) {
  // Two boxes' penetration depth is their least overlap over the 15 separating axes (the Minkowski difference's
  // face normals): an independent closed form to hold EPA to.
  std::mt19937 rng(5);
  const Eigen::Vector3d ha(0.15, 0.1, 0.05), hb(0.05, 0.12, 0.08);
  int tried = 0;
  for (int n = 0; n < 400; ++n) {
    const Eigen::Isometry3d pa = random_pose(rng, 0.1), pb = random_pose(rng, 0.1);
    const Eigen::Matrix3d Ra = pa.linear(), Rb = pb.linear();
    std::vector<Eigen::Vector3d> axes;
    for (int i = 0; i < 3; ++i) {
      axes.push_back(Ra.col(i));
      axes.push_back(Rb.col(i));
      for (int j = 0; j < 3; ++j) axes.push_back(Ra.col(i).cross(Rb.col(j)));
    }
    double gap = -std::numeric_limits<double>::infinity();
    for (Eigen::Vector3d axis : axes) {
      if (axis.norm() < 1e-9) continue;
      axis.normalize();
      const double ra = (Ra.transpose() * axis).cwiseAbs().dot(ha), rb = (Rb.transpose() * axis).cwiseAbs().dot(hb);
      gap = std::max(gap, std::abs(axis.dot(pb.translation() - pa.translation())) - ra - rb);
    }
    if (gap > -1e-4) continue;
    ++tried;
    EXPECT_NEAR(distance(box(2 * ha), pa, box(2 * hb), pb), gap, 1e-9) << n;
  }
  EXPECT_GT(tried, 100);
}

TEST(ShapeSetConvex, HullOfACubeIsTheBox) {
  const Eigen::Vector3d extents(0.2, 0.1, 0.06);
  const ShapeSet set({convex(cube_vertices(extents))});
  EXPECT_EQ(set.geometry(0).hull_vertices.cols(), 8);  // the centre is not a hull vertex
  EXPECT_EQ(set.geometry(0).hull_faces.size(), 12u);
  EXPECT_NEAR(set.geometry(0).sphere_radius, (extents / 2).norm(), 1e-12);
  std::mt19937 rng(6);
  const ConvexShape others[] = {box({0.05, 0.07, 0.09}), cylinder(0.03, 0.1), sphere(0.04),
                                convex(cube_vertices({0.05, 0.07, 0.09}))};
  for (int n = 0; n < 200; ++n) {
    const Eigen::Isometry3d pa = random_pose(rng, 0.1), pb = random_pose(rng, 0.2);
    const ConvexShape& other = others[n % 4];
    const double as_box = distance(box(extents), pa, other, pb);
    const double as_hull = distance(convex(cube_vertices(extents)), pa, other, pb);
    EXPECT_NEAR(as_hull, as_box, as_box < 0.0 ? 5e-5 : 2e-6) << n;  // EPA in penetration (see above)
  }
}

// Points on a shape's surface in its own frame, dense enough to find its lowest point to ~1e-5 of its size.
std::vector<Eigen::Vector3d> surface_samples(const ConvexShape& s) {
  std::vector<Eigen::Vector3d> points;
  const int n = 2000;
  if (s.kind == ShapeKind::Sphere) {
    for (int i = 0; i < 20 * n; ++i) {  // Fibonacci lattice
      const double z = 1.0 - (2.0 * i + 1.0) / (20.0 * n), rho = std::sqrt(1.0 - z * z), phi = i * 2.399963229728653;
      points.push_back(s.size(0) * Eigen::Vector3d(rho * std::cos(phi), rho * std::sin(phi), z));
    }
  } else if (s.kind == ShapeKind::Cylinder) {
    for (int i = 0; i < 10 * n; ++i)
      for (double end : {-0.5, 0.5}) {
        const double a = 2.0 * M_PI * i / (10.0 * n);
        points.push_back({s.size(0) * std::cos(a), s.size(0) * std::sin(a), end * s.size(1)});
      }
  } else {
    const Eigen::Matrix3Xd v = s.kind == ShapeKind::Box ? cube_vertices(s.size) : s.vertices;
    for (Eigen::Index c = 0; c < v.cols(); ++c) points.push_back(v.col(c));
  }
  return points;
}

TEST(ShapeSetLowest, LowestZOfEveryKindMatchesSampledSurfaces) {
  std::mt19937 rng(7);
  Eigen::Matrix3Xd blob(3, 12);
  blob.setRandom();
  blob *= 0.05;
  const std::vector<ConvexShape> shapes = {box({0.2, 0.1, 0.06}, 0), cylinder(0.03, 0.2, 1), sphere(0.04, 1),
                                           convex(blob, 0)};
  ShapeSet set(shapes);
  const long T = 50, L = 2, k = 4;
  std::vector<double> frames(16 * T * L);
  for (long t = 0; t < T; ++t)
    for (long l = 0; l < L; ++l) {
      const Eigen::Matrix<double, 4, 4, Eigen::RowMajor> m = random_pose(rng, 0.5).matrix();
      std::copy(m.data(), m.data() + 16, frames.begin() + 16 * (t * L + l));
    }
  const long idx[] = {0, 1, 2, 3};
  std::vector<double> z(T * k);
  snakehead::lowest_z(frames.data(), T, L, set, idx, k, z.data());
  for (long t = 0; t < T; ++t)
    for (int i = 0; i < 4; ++i) {
      const Eigen::Matrix<double, 4, 4, Eigen::RowMajor> m(frames.data() + 16 * (t * L + shapes[i].frame));
      const Eigen::Isometry3d p{Eigen::Matrix4d(m)};
      double lowest = std::numeric_limits<double>::infinity();
      for (const auto& q : surface_samples(shapes[i])) lowest = std::min(lowest, (p * q).z());
      EXPECT_LE(z[t * k + i], lowest + 1e-12) << t << " " << i;  // a lower bound of every surface point
      EXPECT_NEAR(z[t * k + i], lowest, shapes[i].kind == ShapeKind::Sphere ? 1e-5 : 1e-9) << t << " " << i;
    }
}

TEST(ShapeSetLowest, FlatCylinderGivesItsTwoExactLowestRimPointsFirst) {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const ShapeSet set({cylinder(0.03, 0.2)});
  const Eigen::Matrix<double, 4, 4, Eigen::RowMajor> frame = pose({0.1, 0.2, 0.03}, R).matrix();
  const long idx[] = {0};
  double z = 0.0;
  snakehead::lowest_z(frame.data(), 1, 1, set, idx, 1, &z);
  EXPECT_NEAR(z, 0.0, 1e-15);
  const long M = 20;  // more than its 18 candidates: padded with the lowest
  std::vector<double> pts(M * 3);
  snakehead::lowest_points(frame.data(), 1, 1, set, idx, 1, M, pts.data());
  for (int c = 0; c < 2; ++c) {
    EXPECT_NEAR(pts[3 * c + 2], z, 1e-15);
    EXPECT_NEAR(pts[3 * c + 1], 0.2, 1e-15);
    EXPECT_NEAR(std::abs(pts[3 * c] - 0.1), 0.1, 1e-15);  // one at each end
  }
  EXPECT_NE(pts[0], pts[3]);
  for (long c = 1; c < 18; ++c) EXPECT_LE(pts[3 * (c - 1) + 2], pts[3 * c + 2]);  // sorted by height
  for (long c = 18; c < M; ++c)
    for (int d = 0; d < 3; ++d) EXPECT_EQ(pts[3 * c + d], pts[d]);
}

TEST(ShapeSetLowest, UprightCylinderStandsOnAnOctagonAndBoxOnFourCorners) {
  const ShapeSet set({cylinder(0.03, 0.2), box({0.2, 0.1, 0.06})});
  const Eigen::Matrix<double, 4, 4, Eigen::RowMajor> frame = pose({0.0, 0.0, 0.1}).matrix();
  const long idx[] = {0, 1};
  const long M = 9;
  std::vector<double> pts(2 * M * 3);
  snakehead::lowest_points(frame.data(), 1, 1, set, idx, 2, M, pts.data());
  for (long c = 0; c < M; ++c) EXPECT_NEAR(pts[3 * c + 2], 0.0, 1e-15);  // 8 rim points + the exact one
  for (long c = 0; c < 4; ++c) EXPECT_NEAR(pts[3 * (M + c) + 2], 0.07, 1e-15);
  for (long c = 4; c < M; ++c) EXPECT_NEAR(pts[3 * (M + c) + 2], c < 8 ? 0.13 : 0.07, 1e-15);
}

// A chain of L frames of mixed shapes in random configurations, all pairs but neighbours.
struct Scene {
  ShapeSet set;
  std::vector<long> pairs;
  std::vector<double> frames;
  long T, L;
};

Scene random_scene(unsigned seed, long T) {
  std::mt19937 rng(seed);
  Eigen::Matrix3Xd blob(3, 10);
  blob.setRandom();
  blob *= 0.04;
  std::vector<ConvexShape> shapes;
  const long L = 10;
  for (int l = 0; l < L; ++l) {
    const ConvexShape options[] = {box({0.08, 0.04, 0.04}, l), cylinder(0.02, 0.08, l), sphere(0.03, l),
                                   convex(blob, l)};
    shapes.push_back(options[l % 4]);
    shapes.back().origin = pose({0.04, 0.0, 0.0}, Eigen::AngleAxisd(0.3 * l, Eigen::Vector3d::UnitX()).toRotationMatrix());
  }
  std::vector<long> pairs;
  for (long i = 0; i < L; ++i)
    for (long j = i + 2; j < L; ++j) pairs.insert(pairs.end(), {i, j});
  std::vector<double> frames(16 * T * L);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  for (long t = 0; t < T; ++t) {
    Eigen::Isometry3d link = Eigen::Isometry3d::Identity();
    for (long l = 0; l < L; ++l) {
      const Eigen::Matrix<double, 4, 4, Eigen::RowMajor> m = link.matrix();
      std::copy(m.data(), m.data() + 16, frames.begin() + 16 * (t * L + l));
      link = link * pose({0.09, 0.0, 0.0}, (Eigen::AngleAxisd(u(rng), Eigen::Vector3d::UnitZ()) *
                                            Eigen::AngleAxisd(u(rng), Eigen::Vector3d::UnitY())).toRotationMatrix());
    }
  }
  return Scene{ShapeSet(shapes), pairs, frames, T, L};
}

TEST(ShapeSetPairs, PrunedMinimumEqualsTheMinimumOfAllPairs) {
  const Scene s = random_scene(8, 300);
  const long P = static_cast<long>(s.pairs.size()) / 2;
  std::vector<double> all(s.T * P), pruned(s.T);
  const double inf = std::numeric_limits<double>::infinity();
  for (double cutoff : {inf, 0.02}) {
    snakehead::pair_distances(s.frames.data(), s.T, s.L, s.set, s.frames.data(), s.T, s.L, s.set, s.pairs.data(), P,
                              cutoff, all.data());
    snakehead::pair_min_distances(s.frames.data(), s.T, s.L, s.set, s.frames.data(), s.T, s.L, s.set, s.pairs.data(),
                                  P, cutoff, pruned.data());
    int touching = 0;
    for (long t = 0; t < s.T; ++t) {
      const double expected = *std::min_element(all.begin() + t * P, all.begin() + (t + 1) * P);
      EXPECT_NEAR(pruned[t], expected, 1e-9) << t;
      touching += expected < 0.0;
    }
    EXPECT_GT(touching, 5);  // the configurations do collide
  }
}

TEST(ShapeSetPairs, CutoffGivesTheBoundAndOneSampleBroadcasts) {
  const ShapeSet robot({sphere(0.1)}), world({box({0.2, 0.2, 0.2})});
  std::vector<double> frames(16 * 3);
  for (long t = 0; t < 3; ++t) {
    const Eigen::Matrix<double, 4, 4, Eigen::RowMajor> m = pose({1.0 + t, 0.0, 0.0}).matrix();
    std::copy(m.data(), m.data() + 16, frames.begin() + 16 * t);
  }
  const Eigen::Matrix<double, 4, 4, Eigen::RowMajor> fixed = Eigen::Matrix4d::Identity();
  const long pairs[] = {0, 0};
  double out[3], min_out[3];
  snakehead::pair_distances(frames.data(), 3, 1, robot, fixed.data(), 1, 1, world, pairs, 1, 1.5, out);
  EXPECT_NEAR(out[0], 0.8, 1e-12);                         // exact: the bound 1 - 0.1 - sqrt(0.03) < 1.5
  EXPECT_NEAR(out[1], 2.0 - 0.1 - std::sqrt(0.03), 1e-12);  // beyond the cutoff: the bound
  EXPECT_NEAR(out[2], 3.0 - 0.1 - std::sqrt(0.03), 1e-12);
  snakehead::pair_min_distances(frames.data(), 3, 1, robot, fixed.data(), 1, 1, world, pairs, 1, 1.5, min_out);
  for (int t = 0; t < 3; ++t) EXPECT_EQ(min_out[t], out[t]);
  snakehead::pair_min_distances(frames.data(), 3, 1, robot, fixed.data(), 1, 1, world, pairs, 0, 1.5, min_out);
  EXPECT_EQ(min_out[0], std::numeric_limits<double>::infinity());
}

TEST(ShapeSetPairs, ManyThreadsGiveTheSameNumbers) {
  const Scene s = random_scene(9, 100);
  const long P = static_cast<long>(s.pairs.size()) / 2;
  const auto run = [&s, P](std::vector<double>& all, std::vector<double>& mins, std::vector<double>& points) {
    all.resize(s.T * P);
    mins.resize(s.T);
    snakehead::pair_distances(s.frames.data(), s.T, s.L, s.set, s.frames.data(), s.T, s.L, s.set, s.pairs.data(), P,
                              std::numeric_limits<double>::infinity(), all.data());
    snakehead::pair_min_distances(s.frames.data(), s.T, s.L, s.set, s.frames.data(), s.T, s.L, s.set,
                                  s.pairs.data(), P, 0.05, mins.data());
    std::vector<long> idx(s.L);
    for (long l = 0; l < s.L; ++l) idx[l] = l;
    points.resize(s.T * s.L * 4 * 3);
    snakehead::lowest_points(s.frames.data(), s.T, s.L, s.set, idx.data(), s.L, 4, points.data());
  };
  std::vector<double> all, mins, points;
  run(all, mins, points);
  std::vector<std::vector<double>> a(8), m(8), p(8);
  std::vector<std::thread> threads;
  for (int i = 0; i < 8; ++i) threads.emplace_back([&, i] { run(a[i], m[i], p[i]); });
  for (auto& th : threads) th.join();
  for (int i = 0; i < 8; ++i) {
    EXPECT_EQ(a[i], all);
    EXPECT_EQ(m[i], mins);
    EXPECT_EQ(p[i], points);
  }
}

TEST(ShapeSetInput, BadShapesAreInputErrors) {
  using snakehead::InputError;
  EXPECT_THROW(ShapeSet({box({0.1, -0.1, 0.1})}), InputError);
  EXPECT_THROW(ShapeSet({box({0.1, NAN, 0.1})}), InputError);
  EXPECT_THROW(ShapeSet({cylinder(0.0, 0.1)}), InputError);
  EXPECT_THROW(ShapeSet({sphere(INFINITY)}), InputError);
  EXPECT_THROW(ShapeSet({sphere(0.1, -1)}), InputError);
  ConvexShape skewed = box({0.1, 0.1, 0.1});
  skewed.origin.linear()(0, 1) = 0.5;
  EXPECT_THROW(ShapeSet({skewed}), InputError);
  ConvexShape nan_origin = box({0.1, 0.1, 0.1});
  nan_origin.origin.translation()(2) = NAN;
  EXPECT_THROW(ShapeSet({nan_origin}), InputError);
  Eigen::Matrix3Xd flat(3, 5);
  flat << 0, 1, 0, 1, 0.5, 0, 0, 1, 1, 0.5, 0, 0, 0, 0, 0;
  EXPECT_THROW(ShapeSet({convex(flat)}), InputError);
  EXPECT_THROW(ShapeSet({convex(flat.leftCols(3))}), InputError);
  Eigen::Matrix3Xd cube = cube_vertices({1, 1, 1});
  cube(1, 2) = INFINITY;
  EXPECT_THROW(ShapeSet({convex(cube)}), InputError);
}

TEST(ShapeSetInput, BadCallsAreInputErrors) {
  using snakehead::InputError;
  const ShapeSet set({box({0.1, 0.1, 0.1}, 0), sphere(0.1, 1)});
  std::vector<double> frames(16 * 2 * 2, 0.0);
  for (int f = 0; f < 4; ++f)
    for (int d = 0; d < 4; ++d) frames[16 * f + 5 * d] = 1.0;
  double out[64];
  const long good[] = {0, 1}, outside[] = {0, 2}, negative[] = {-1, 0};
  EXPECT_NO_THROW(snakehead::lowest_z(frames.data(), 2, 2, set, good, 2, out));
  EXPECT_THROW(snakehead::lowest_z(frames.data(), 2, 2, set, outside, 2, out), InputError);
  EXPECT_THROW(snakehead::lowest_z(frames.data(), 2, 2, set, negative, 2, out), InputError);
  EXPECT_THROW(snakehead::lowest_z(frames.data(), 4, 1, set, good, 2, out), InputError);  // shape 1's frame missing
  EXPECT_THROW(snakehead::lowest_points(frames.data(), 2, 2, set, good, 2, 0, out), InputError);
  EXPECT_THROW(snakehead::pair_distances(frames.data(), 2, 2, set, frames.data(), 2, 2, set, outside, 1, 1.0, out),
               InputError);
  EXPECT_THROW(snakehead::pair_distances(frames.data(), 2, 2, set, frames.data(), 3, 1, set, good, 1, 1.0, out),
               InputError);  // 2 and 3 samples do not broadcast
  EXPECT_THROW(snakehead::pair_min_distances(frames.data(), 2, 2, set, frames.data(), 2, 2, set, good, 1, NAN, out),
               InputError);
  frames[16 + 3] = NAN;
  EXPECT_THROW(snakehead::lowest_z(frames.data(), 2, 2, set, good, 2, out), InputError);
  EXPECT_THROW(snakehead::pair_min_distances(frames.data(), 2, 2, set, frames.data(), 2, 2, set, good, 1, 1.0, out),
               InputError);
}

}  // namespace
