#include "snakehead/shape_set.hpp"

#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/convex.h>
#include <fcl/geometry/shape/cylinder.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/math/detail/project.h>
#include <fcl/narrowphase/detail/gjk_solver_libccd.h>

#include <ccd/ccd.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <new>
#include <string>
#include <type_traits>
#include <utility>

#include "qhull_run.hpp"
#include "snakehead/model.hpp"

namespace snakehead {

namespace {

using Transform = fcl::Transform3<double>;

// GJK stops when an iteration improves the distance by less than this (m): 1e-6 relative to a 1 mm gap, well
// below what planning resolves. Also EPA's bound on a penetration depth.
constexpr double kGjkTolerance = 1e-9;

std::string shape_name(int i) { return "ShapeSet: shape " + std::to_string(i); }

void check_rigid(const Eigen::Isometry3d& origin, int i) {
  if (!origin.matrix().allFinite()) throw InputError(shape_name(i) + ": origin must be finite");
  const Eigen::Matrix3d R = origin.linear();
  if (!(R.transpose() * R).isApprox(Eigen::Matrix3d::Identity(), 1e-6) || R.determinant() < 0.0)
    throw InputError(shape_name(i) + ": origin's rotation must be orthonormal and right-handed");
  if (origin.matrix().row(3) != Eigen::RowVector4d(0.0, 0.0, 0.0, 1.0))
    throw InputError(shape_name(i) + ": origin's last row must be (0, 0, 0, 1)");
}

// Sizes the kind uses must be finite and > 0; the others finite.
void check_size(const ConvexShape& s, int i) {
  if (!s.size.allFinite()) throw InputError(shape_name(i) + ": size must be finite");
  const int used = s.kind == ShapeKind::Box ? 3 : s.kind == ShapeKind::Cylinder ? 2 : s.kind == ShapeKind::Sphere ? 1 : 0;
  for (int d = 0; d < used; ++d)
    if (!(s.size(d) > 0.0))
      throw InputError(shape_name(i) + ": size (box extents, cylinder radius and length, sphere radius) must be > 0");
}

// The convex hull of a Convex shape's vertices (qhull, triangulated), into g's hull_* members.
void make_hull(const ConvexShape& s, int i, ShapeGeometry& g) {
  if (!s.vertices.allFinite()) throw InputError(shape_name(i) + ": vertices must be finite");
  if (s.vertices.cols() < 4) throw InputError(shape_name(i) + ": a convex shape needs at least 4 vertices");
  std::vector<Eigen::Vector3d> points(static_cast<std::size_t>(s.vertices.cols()));
  for (Eigen::Index v = 0; v < s.vertices.cols(); ++v) points[static_cast<std::size_t>(v)] = s.vertices.col(v);
  QhullRun run(points, "qhull Qt");  // Qt: triangles, which FCL's Convex and hull_faces want
  if (!run.ok())
    throw InputError(shape_name(i) + ": its vertices span no volume (qhull: " + run.error() + ")");
  qhT* qh = run.qh;
  std::map<int, int> index;  // qhull point id -> hull vertex index
  vertexT* vertex;
  vertexT** vertexp;
  FORALLvertices index.emplace(qh_pointid(qh, vertex->point), 0);
  g.hull_vertices.resize(3, static_cast<Eigen::Index>(index.size()));
  int n = 0;
  for (auto& [id, k] : index) {
    k = n;
    g.hull_vertices.col(n++) = points[static_cast<std::size_t>(id)];
  }
  facetT* facet;
  FORALLfacets {
    std::array<int, 3> f{};
    int m = 0;
    FOREACHvertex_(facet->vertices) if (m < 3) f[m++] = index.at(qh_pointid(qh, vertex->point));
    if (m != 3) continue;
    const Eigen::Vector3d a = g.hull_vertices.col(f[0]), b = g.hull_vertices.col(f[1]), c = g.hull_vertices.col(f[2]);
    const Eigen::Vector3d outward(facet->normal[0], facet->normal[1], facet->normal[2]);
    if ((b - a).cross(c - a).dot(outward) < 0.0) std::swap(f[1], f[2]);  // counter-clockwise from outside
    g.hull_faces.push_back(f);
    // qhull's own plane (its normal is unit and outward; offset such that n.x + offset = 0 on the plane)
    g.hull_planes.emplace_back(outward.x(), outward.y(), outward.z(), -facet->offset);
  }
}

std::shared_ptr<const fcl::CollisionGeometry<double>> make_convex(const ShapeGeometry& g) {
  auto vertices = std::make_shared<std::vector<fcl::Vector3<double>>>();
  for (Eigen::Index v = 0; v < g.hull_vertices.cols(); ++v) vertices->push_back(g.hull_vertices.col(v));
  auto faces = std::make_shared<std::vector<int>>();
  for (const auto& f : g.hull_faces) faces->insert(faces->end(), {3, f[0], f[1], f[2]});
  return std::make_shared<fcl::Convex<double>>(vertices, static_cast<int>(g.hull_faces.size()), faces);
}

// Points given in the shape frame: their bounding box and a bounding sphere about its centre.
void bound_points(const Eigen::Matrix3Xd& points, ShapeGeometry& g) {
  const Eigen::Vector3d lo = points.rowwise().minCoeff(), hi = points.rowwise().maxCoeff();
  g.box_centre = g.sphere_centre = 0.5 * (lo + hi);
  g.box_half = 0.5 * (hi - lo);
  g.sphere_radius = (points.colwise() - g.sphere_centre).colwise().norm().maxCoeff();
}

ShapeGeometry make_geometry(const ConvexShape& s, int i) {
  ShapeGeometry g;
  switch (s.kind) {
    case ShapeKind::Box: {
      g.fcl = std::make_shared<fcl::Box<double>>(s.size);
      g.box_half = 0.5 * s.size;
      g.sphere_radius = g.box_half.norm();
      g.candidates.resize(3, 8);
      for (int c = 0; c < 8; ++c)  // corner c: bit d set -> + along axis d
        for (int d = 0; d < 3; ++d) g.candidates(d, c) = (c >> d & 1) ? g.box_half(d) : -g.box_half(d);
      break;
    }
    case ShapeKind::Cylinder: {
      const double r = s.size(0), half_length = 0.5 * s.size(1);
      g.fcl = std::make_shared<fcl::Cylinder<double>>(r, s.size(1));
      g.box_half = Eigen::Vector3d(r, r, half_length);
      g.sphere_radius = std::hypot(r, half_length);
      g.candidates.resize(3, 16);
      for (int c = 0; c < 8; ++c) {
        const double angle = 2.0 * M_PI * c / 8.0;
        g.candidates.col(c) = Eigen::Vector3d(r * std::cos(angle), r * std::sin(angle), -half_length);
        g.candidates.col(8 + c) = Eigen::Vector3d(r * std::cos(angle), r * std::sin(angle), half_length);
      }
      break;
    }
    case ShapeKind::Sphere:
      g.fcl = std::make_shared<fcl::Sphere<double>>(s.size(0));
      g.box_half = Eigen::Vector3d::Constant(s.size(0));
      g.sphere_radius = s.size(0);
      g.candidates.resize(3, 0);
      break;
    case ShapeKind::Convex:
      make_hull(s, i, g);
      g.fcl = make_convex(g);
      bound_points(g.hull_vertices, g);
      g.candidates = g.hull_vertices;
      break;
    default:
      throw InputError(shape_name(i) + ": unknown kind");
  }
  return g;
}

}  // namespace

ShapeSet::ShapeSet(std::vector<ConvexShape> shapes) : shapes_(std::move(shapes)) {
  geometry_.reserve(shapes_.size());
  for (int i = 0; i < size(); ++i) {
    const ConvexShape& s = shapes_[static_cast<std::size_t>(i)];
    if (s.frame < 0) throw InputError(shape_name(i) + ": frame must be >= 0");
    check_rigid(s.origin, i);
    check_size(s, i);
    geometry_.push_back(make_geometry(s, i));
    max_frame_ = std::max(max_frame_, s.frame);
  }
}

// ---------------------------------------------------------------------------------------------------------------
// Signed distance of two shapes.

namespace {

// Separating-axis lower bound of the distance of two shapes, from their bounding boxes (Gottschalk et al.'s 15
// axes, worked in a's box frame): the largest gap of the boxes' projections over the axes, each gap in metres.
// It never exceeds the boxes' signed distance, which never exceeds the shapes'. Stops once above stop_above.
double box_bound(const ShapeGeometry& ga, const Eigen::Isometry3d& pa, const ShapeGeometry& gb,
                 const Eigen::Isometry3d& pb, double stop_above) {
  const Eigen::Matrix3d C = pa.linear().transpose() * pb.linear();  // b's axes in a's frame
  const Eigen::Vector3d t = pa.linear().transpose() * (pb * gb.box_centre - pa * ga.box_centre);
  const Eigen::Matrix3d absC = C.cwiseAbs();
  const Eigen::Vector3d &ha = ga.box_half, &hb = gb.box_half;
  double best = -std::numeric_limits<double>::infinity();
  for (int i = 0; i < 3; ++i) best = std::max(best, std::abs(t(i)) - ha(i) - absC.row(i).dot(hb));
  for (int j = 0; j < 3; ++j) best = std::max(best, std::abs(C.col(j).dot(t)) - absC.col(j).dot(ha) - hb(j));
  if (best > stop_above) return best;
  for (int i = 0; i < 3; ++i) {
    const int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
    for (int j = 0; j < 3; ++j) {
      const int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
      // axis a_i x b_j = (0, -C(i2, j), C(i1, j)) cyclically from i; parallel edges give none
      const double length = std::hypot(C(i1, j), C(i2, j));
      if (!(length > 1e-9)) continue;
      const double gap = std::abs(t(i2) * C(i1, j) - t(i1) * C(i2, j)) - ha(i1) * absC(i2, j) -
                         ha(i2) * absC(i1, j) - hb(j1) * absC(i, j2) - hb(j2) * absC(i, j1);
      best = std::max(best, gap / length);
    }
    if (best > stop_above) return best;
  }
  return best;
}

template <typename T>
constexpr bool is_sphere = std::is_same_v<T, fcl::Sphere<double>>;
template <typename T>
constexpr bool is_convex = std::is_same_v<T, fcl::Convex<double>>;

// Calls f with the shape's FCL geometry as its own type.
template <typename F>
decltype(auto) visit_geometry(const ConvexShape& s, const ShapeGeometry& g, F&& f) {
  switch (s.kind) {
    case ShapeKind::Box:
      return f(static_cast<const fcl::Box<double>&>(*g.fcl));
    case ShapeKind::Cylinder:
      return f(static_cast<const fcl::Cylinder<double>&>(*g.fcl));
    case ShapeKind::Sphere:
      return f(static_cast<const fcl::Sphere<double>&>(*g.fcl));
    default:
      return f(static_cast<const fcl::Convex<double>&>(*g.fcl));
  }
}

fcl::detail::GJKSolver_libccd<double> make_solver() {
  fcl::detail::GJKSolver_libccd<double> solver;
  solver.distance_tolerance = kGjkTolerance;
  return solver;
}

// Signed distance of a point (in the hull's frame) to a convex hull: min over its triangles outside, max over
// its face planes inside. Exact, unlike EPA on a sphere (see below).
double point_hull_distance(const ShapeGeometry& hull, const Eigen::Vector3d& p) {
  double inside = -std::numeric_limits<double>::infinity();
  for (const Eigen::Vector4d& plane : hull.hull_planes) inside = std::max(inside, plane.head<3>().dot(p) - plane(3));
  if (inside <= 0.0) return inside;
  double squared = std::numeric_limits<double>::infinity();
  for (const auto& f : hull.hull_faces) {
    const auto r = fcl::detail::Project<double>::projectTriangle(hull.hull_vertices.col(f[0]),
                                                                 hull.hull_vertices.col(f[1]),
                                                                 hull.hull_vertices.col(f[2]), p);
    squared = std::min(squared, r.sqr_distance);
  }
  return std::sqrt(squared);
}

// Penetration depth by libccd's own EPA (ccdGJKPenetration) on FCL's support functions, as a negative distance
// (0 where GJK finds the shapes only touching).
template <typename A, typename B>
double epa_signed_distance(const A& a, const Transform& pose_a, const B& b, const Transform& pose_b) {
  using InitA = fcl::detail::GJKInitializer<double, A>;
  using InitB = fcl::detail::GJKInitializer<double, B>;
  void* oa = InitA::createGJKObject(a, pose_a);
  void* ob = InitB::createGJKObject(b, pose_b);
  ccd_t ccd;
  CCD_INIT(&ccd);
  ccd.support1 = InitA::getSupportFunction();
  ccd.support2 = InitB::getSupportFunction();
  ccd.center1 = InitA::getCenterFunction();
  ccd.center2 = InitB::getCenterFunction();
  ccd.max_iterations = 1000;
  ccd.epa_tolerance = ccd.dist_tolerance = ccd.mpr_tolerance = kGjkTolerance;
  ccd_real_t depth = 0.0;
  ccd_vec3_t direction, position;
  const int status = ccdGJKPenetration(oa, ob, &ccd, &depth, &direction, &position);
  InitA::deleteGJKObject(oa);
  InitB::deleteGJKObject(ob);
  if (status == -2) throw std::bad_alloc();
  return status == 0 ? -depth : 0.0;
}

// FCL 0.7's choices, measured against closed forms (tests/cpp/test_shape_set.cpp and the notes in the commit):
// apart, its GJK (shapeDistance) is exact to its tolerance for every pair. In penetration:
// - its EPA (shapeSignedDistance) is exact for polytopes, but Debian's libfcl is built with assertions and its
//   EPA aborts the process on some configurations (ComputeVisiblePatch: isOutsidePolytopeFace) of a snake's
//   shapes: never called here;
// - collide's generic depth (MPR) is no use: centimetres too deep (a depth along the centres' line);
// - collide's closed forms for a sphere against a sphere, a box or a cylinder are exact: used;
// - libccd's own EPA (ccdGJKPenetration) never aborted in millions of random pairs and is good to ~3e-5 m on
//   0.1 m shapes: used for cylinders and convex hulls. (Two boxes and a sphere against a hull have exact closed
//   forms of our own, in shape_signed_distance.)
template <typename A, typename B>
double fcl_signed_distance(const A& a, const Transform& pose_a, const B& b, const Transform& pose_b) {
  const auto solver = make_solver();
  double distance = 0.0;
  fcl::Vector3<double> pa, pb;
  if (solver.shapeDistance(a, pose_a, b, pose_b, &distance, &pa, &pb)) return distance;
  if constexpr (is_sphere<A> || is_sphere<B>) {
    std::vector<fcl::ContactPoint<double>> contacts;  // allocated only in penetration
    if (!solver.shapeIntersect(a, pose_a, b, pose_b, &contacts)) return 0.0;
    double depth = 0.0;
    for (const auto& c : contacts) depth = std::max(depth, c.penetration_depth);
    return -depth;
  } else {
    return epa_signed_distance(a, pose_a, b, pose_b);
  }
}

// A sphere against a convex hull: the centre's signed distance to the hull less the radius (exact).
double sphere_hull_distance(const ShapeGeometry& sphere, const Eigen::Isometry3d& pose_s, const ShapeGeometry& hull,
                            const Eigen::Isometry3d& pose_h) {
  const double r = static_cast<const fcl::Sphere<double>&>(*sphere.fcl).radius;
  const Eigen::Vector3d centre = pose_h.inverse() * pose_s.translation();
  return point_hull_distance(hull, centre) - r;
}

}  // namespace

double shape_signed_distance(const ShapeSet& a, int i, const Eigen::Isometry3d& pose_a, const ShapeSet& b, int j,
                             const Eigen::Isometry3d& pose_b) {
  const ConvexShape &sa = a.shape(i), &sb = b.shape(j);
  const ShapeGeometry &ga = a.geometry(i), &gb = b.geometry(j);
  if (sa.kind == ShapeKind::Box && sb.kind == ShapeKind::Box) {
    // Two boxes overlap by their least overlap over the 15 separating axes (the faces of their Minkowski
    // difference): exact, where no axis separates them.
    const double gap = box_bound(ga, pose_a, gb, pose_b, std::numeric_limits<double>::infinity());
    if (gap <= 0.0) return gap;
  }
  if (sa.kind == ShapeKind::Sphere && sb.kind == ShapeKind::Convex) return sphere_hull_distance(ga, pose_a, gb, pose_b);
  if (sa.kind == ShapeKind::Convex && sb.kind == ShapeKind::Sphere) return sphere_hull_distance(gb, pose_b, ga, pose_a);
  const Transform ta(pose_a.matrix()), tb(pose_b.matrix());
  return visit_geometry(sa, ga, [&](const auto& fa) {
    return visit_geometry(sb, gb, [&](const auto& fb) { return fcl_signed_distance(fa, ta, fb, tb); });
  });
}

// ---------------------------------------------------------------------------------------------------------------
// Batches over samples of frames.

namespace {

// Frames of T samples of L frames (see the header), checked finite.
class Frames {
 public:
  Frames(const char* what, const double* data, long T, long L) : data_(data), L_(L) {
    if (T < 0 || L < 0) throw InputError(std::string(what) + ": negative frame count");
    for (long n = 0; n < 16 * T * L; ++n)
      if (!std::isfinite(data[n])) throw InputError(std::string(what) + ": frames must be finite");
  }
  // Shape s's own frame in the world at sample t.
  Eigen::Isometry3d pose(long t, const ConvexShape& s) const {
    Eigen::Isometry3d frame;
    frame.matrix() = Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(data_ + 16 * (t * L_ + s.frame));
    return frame * s.origin;
  }

 private:
  const double* data_;
  long L_;
};

// Throws unless `index` names a shape of `set` whose frame is among the L frames.
void check_shape(const char* what, const ShapeSet& set, long index, long L) {
  if (index < 0 || index >= set.size())
    throw InputError(std::string(what) + ": shape index " + std::to_string(index) + " is outside the set of " +
                     std::to_string(set.size()) + " shapes");
  if (set.shape(static_cast<int>(index)).frame >= L)
    throw InputError(std::string(what) + ": shape " + std::to_string(index) + " is attached to frame " +
                     std::to_string(set.shape(static_cast<int>(index)).frame) + " but there are " +
                     std::to_string(L) + " frames");
}

double lowest_z_at(const ConvexShape& s, const ShapeGeometry& g, const Eigen::Isometry3d& pose) {
  const double cz = pose.translation().z();
  const Eigen::RowVector3d R2 = pose.linear().row(2);  // world z of each of the shape's axes
  switch (s.kind) {
    case ShapeKind::Box:
      return cz - R2.cwiseAbs().dot(g.box_half.transpose());
    case ShapeKind::Cylinder: {
      const double az = R2(2);  // the axis' world z
      return cz - std::abs(az) * 0.5 * s.size(1) - s.size(0) * std::sqrt(std::max(0.0, 1.0 - az * az));
    }
    case ShapeKind::Sphere:
      return cz - s.size(0);
    default:
      return cz + (R2 * g.hull_vertices).minCoeff();
  }
}

// A cylinder's lowest point on the rim circle at `end` (+1 or -1 along its axis), in the world. When the axis is
// vertical, every rim point is lowest: the one along the shape frame's x.
Eigen::Vector3d lowest_rim_point(const ConvexShape& s, const Eigen::Isometry3d& pose, double end) {
  const Eigen::Vector3d axis = pose.linear().col(2);
  const Eigen::Vector3d centre = pose.translation() + end * 0.5 * s.size(1) * axis;
  Eigen::Vector3d down = -Eigen::Vector3d::UnitZ() + axis.z() * axis;  // -z projected off the axis
  const double n = down.norm();
  down = n > 1e-12 ? Eigen::Vector3d(down / n) : Eigen::Vector3d(pose.linear().col(0));
  return centre + s.size(0) * down;
}

// World candidates of shape s at a pose into `points` (3 x n; resized only when it grows).
int world_candidates(const ConvexShape& s, const ShapeGeometry& g, const Eigen::Isometry3d& pose,
                     Eigen::Matrix3Xd& points) {
  const int fixed = static_cast<int>(g.candidates.cols());
  const int extra = s.kind == ShapeKind::Sphere ? 1 : s.kind == ShapeKind::Cylinder ? 2 : 0;
  if (points.cols() < fixed + extra) points.resize(3, fixed + extra);
  points.leftCols(fixed).noalias() = (pose.linear() * g.candidates).colwise() + pose.translation();
  if (s.kind == ShapeKind::Sphere) points.col(0) = pose.translation() - s.size(0) * Eigen::Vector3d::UnitZ();
  if (s.kind == ShapeKind::Cylinder) {
    points.col(fixed) = lowest_rim_point(s, pose, -1.0);
    points.col(fixed + 1) = lowest_rim_point(s, pose, 1.0);
  }
  return fixed + extra;
}

}  // namespace

void lowest_z(const double* frames, long T, long L, const ShapeSet& set, const long* shapes, long k, double* out) {
  const Frames f("lowest_z", frames, T, L);
  if (k < 0) throw InputError("lowest_z: negative shape count");
  for (long j = 0; j < k; ++j) check_shape("lowest_z", set, shapes[j], L);
  for (long t = 0; t < T; ++t)
    for (long j = 0; j < k; ++j) {
      const int i = static_cast<int>(shapes[j]);
      out[t * k + j] = lowest_z_at(set.shape(i), set.geometry(i), f.pose(t, set.shape(i)));
    }
}

void lowest_points(const double* frames, long T, long L, const ShapeSet& set, const long* shapes, long k, long M,
                   double* out) {
  const Frames f("lowest_points", frames, T, L);
  if (k < 0) throw InputError("lowest_points: negative shape count");
  if (M < 1) throw InputError("lowest_points: the number of points per shape must be >= 1");
  for (long j = 0; j < k; ++j) check_shape("lowest_points", set, shapes[j], L);
  Eigen::Matrix3Xd points;  // reused for every shape and sample
  std::vector<int> order;
  for (long t = 0; t < T; ++t)
    for (long j = 0; j < k; ++j) {
      const int i = static_cast<int>(shapes[j]);
      const int n = world_candidates(set.shape(i), set.geometry(i), f.pose(t, set.shape(i)), points);
      order.resize(static_cast<std::size_t>(n));
      for (int c = 0; c < n; ++c) order[static_cast<std::size_t>(c)] = c;
      const long m = std::min<long>(M, n);
      // ties by candidate order, so that equal heights come out the same way on every call
      std::partial_sort(order.begin(), order.begin() + m, order.end(), [&points](int p, int q) {
        return points(2, p) < points(2, q) || (points(2, p) == points(2, q) && p < q);
      });
      double* o = out + 3 * M * (t * k + j);
      for (long c = 0; c < M; ++c) {
        const int from = order[static_cast<std::size_t>(c < m ? c : 0)];  // pad with the lowest
        for (int d = 0; d < 3; ++d) o[3 * c + d] = points(d, from);
      }
    }
}

namespace {

// World bounding sphere centre of a shape at a pose.
Eigen::Vector3d sphere_centre(const ShapeGeometry& g, const Eigen::Isometry3d& pose) { return pose * g.sphere_centre; }

// Checks pair_distances' input and gives each pair's shapes' poses at a sample (broadcasting one-sample sides).
class PairBatch {
 public:
  PairBatch(const char* what, const double* frames_a, long Ta, long La, const ShapeSet& set_a,
            const double* frames_b, long Tb, long Lb, const ShapeSet& set_b, const long* pairs, long P, double cutoff)
      : a_(what, frames_a, Ta, La), b_(what, frames_b, Tb, Lb), set_a_(set_a), set_b_(set_b), pairs_(pairs),
        Ta_(Ta), Tb_(Tb), T_(std::max(Ta, Tb)) {
    if ((Ta != T_ && Ta != 1) || (Tb != T_ && Tb != 1))
      throw InputError(std::string(what) + ": sample counts " + std::to_string(Ta) + " and " + std::to_string(Tb) +
                       " do not broadcast (each must be the same or 1)");
    if (P < 0) throw InputError(std::string(what) + ": negative pair count");
    if (std::isnan(cutoff)) throw InputError(std::string(what) + ": cutoff must not be NaN");
    for (long p = 0; p < P; ++p) {
      check_shape(what, set_a, pairs[2 * p], La);
      check_shape(what, set_b, pairs[2 * p + 1], Lb);
    }
  }
  long samples() const { return T_; }
  int shape_a(long p) const { return static_cast<int>(pairs_[2 * p]); }
  int shape_b(long p) const { return static_cast<int>(pairs_[2 * p + 1]); }
  Eigen::Isometry3d pose_a(long t, long p) const { return a_.pose(Ta_ == 1 ? 0 : t, set_a_.shape(shape_a(p))); }
  Eigen::Isometry3d pose_b(long t, long p) const { return b_.pose(Tb_ == 1 ? 0 : t, set_b_.shape(shape_b(p))); }
  // The bounding spheres' lower bound of pair p's distance at these poses.
  double sphere_bound(long p, const Eigen::Isometry3d& pa, const Eigen::Isometry3d& pb) const {
    const ShapeGeometry &ga = set_a_.geometry(shape_a(p)), &gb = set_b_.geometry(shape_b(p));
    return (sphere_centre(ga, pa) - sphere_centre(gb, pb)).norm() - ga.sphere_radius - gb.sphere_radius;
  }
  double box_bound(long p, const Eigen::Isometry3d& pa, const Eigen::Isometry3d& pb, double stop_above) const {
    return snakehead::box_bound(set_a_.geometry(shape_a(p)), pa, set_b_.geometry(shape_b(p)), pb, stop_above);
  }
  double exact(long p, const Eigen::Isometry3d& pa, const Eigen::Isometry3d& pb) const {
    return shape_signed_distance(set_a_, shape_a(p), pa, set_b_, shape_b(p), pb);
  }

 private:
  Frames a_, b_;
  const ShapeSet& set_a_;
  const ShapeSet& set_b_;
  const long* pairs_;
  long Ta_, Tb_, T_;
};

}  // namespace

void pair_distances(const double* frames_a, long Ta, long La, const ShapeSet& set_a, const double* frames_b, long Tb,
                    long Lb, const ShapeSet& set_b, const long* pairs, long P, double cutoff, double* out) {
  const PairBatch batch("pair_distances", frames_a, Ta, La, set_a, frames_b, Tb, Lb, set_b, pairs, P, cutoff);
  for (long t = 0; t < batch.samples(); ++t)
    for (long p = 0; p < P; ++p) {
      const Eigen::Isometry3d pa = batch.pose_a(t, p), pb = batch.pose_b(t, p);
      const double bound = batch.sphere_bound(p, pa, pb);
      out[t * P + p] = bound < cutoff ? batch.exact(p, pa, pb) : bound;
    }
}

void pair_min_distances(const double* frames_a, long Ta, long La, const ShapeSet& set_a, const double* frames_b,
                        long Tb, long Lb, const ShapeSet& set_b, const long* pairs, long P, double cutoff,
                        double* out) {
  const PairBatch batch("pair_min_distances", frames_a, Ta, La, set_a, frames_b, Tb, Lb, set_b, pairs, P, cutoff);
  std::vector<std::pair<double, long>> bounds(static_cast<std::size_t>(P));  // (sphere bound, pair), per sample
  for (long t = 0; t < batch.samples(); ++t) {
    for (long p = 0; p < P; ++p) bounds[static_cast<std::size_t>(p)] = {batch.sphere_bound(p, batch.pose_a(t, p), batch.pose_b(t, p)), p};
    std::sort(bounds.begin(), bounds.end());
    double best = std::numeric_limits<double>::infinity();
    for (const auto& [bound, p] : bounds) {
      if (bound >= best) break;  // neither this pair nor any after it can be closer
      if (bound >= cutoff) {     // pair_distances reports the bound itself here
        best = bound;
        break;
      }
      const Eigen::Isometry3d pa = batch.pose_a(t, p), pb = batch.pose_b(t, p);
      if (batch.box_bound(p, pa, pb, best) >= best) continue;  // its exact distance is no smaller either
      best = std::min(best, batch.exact(p, pa, pb));
    }
    out[t] = best;
  }
}

}  // namespace snakehead
