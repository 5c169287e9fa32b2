#include "snakehead/alpha_shape.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <string>

#include "snakehead/model.hpp"
#include "snakehead/workspace.hpp"
#include "qhull_run.hpp"

namespace snakehead {
namespace {

// Union-find over tetrahedra (path halving, union by size).
struct Regions {
  explicit Regions(std::size_t n) : parent(n), size(n, 1) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  }
  bool unite(int a, int b) {
    a = find(a), b = find(b);
    if (a == b) return false;
    if (size[a] < size[b]) std::swap(a, b);
    parent[b] = a;
    size[a] += size[b];
    return true;
  }
  std::vector<int> parent, size;
};

// Radius of the sphere through the four points; +inf for a flat tetrahedron.
double circumradius(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                    const Eigen::Vector3d& d) {
  const Eigen::Vector3d u = b - a, v = c - a, w = d - a;
  const double det = u.dot(v.cross(w));
  const double scale = u.norm() * v.norm() * w.norm();
  if (!(std::abs(det) > 1e-12 * scale)) return std::numeric_limits<double>::infinity();
  // Centre - a = (|u|^2 (v x w) + |v|^2 (w x u) + |w|^2 (u x v)) / (2 u . (v x w)).
  const Eigen::Vector3d centre = (u.squaredNorm() * v.cross(w) + v.squaredNorm() * w.cross(u) +
                                  w.squaredNorm() * u.cross(v)) / (2.0 * det);
  return centre.norm();
}

}  // namespace

AlphaShape AlphaShape::boundary(const std::vector<Eigen::Vector3d>& points, double shrink) {
  if (!(shrink >= 0.0 && shrink <= 1.0))
    throw InputError("the boundary's shrink factor must be within [0, 1], got " + std::to_string(shrink));
  if (points.size() < 5) throw InputError("a 3-D boundary needs at least 5 points");
  for (const auto& p : points)
    if (!p.allFinite()) throw InputError("the points of a boundary must be finite");
  AlphaShape s;
  s.points_ = points;
  s.shrink_ = shrink;

  // Delaunay triangulation: the lower hull of the points lifted onto a paraboloid (qhull "d").
  // Qbb scales the lifted coordinate for precision; Qt triangulates, so every facet is a tetrahedron.
  QhullRun run(points, "qhull d Qbb Qt");
  qhT* qh = run.qh;
  if (run.ok()) {
    std::vector<int> tet_of(qh->facet_id, -1);  // qhull facet id -> tetrahedron index
    facetT* facet;
    vertexT *vertex, **vertexp;
    FORALLfacets {
      if (facet->upperdelaunay) continue;
      std::array<int, 4> t{};
      int k = 0;
      FOREACHvertex_(facet->vertices) {
        if (k < 4) t[k] = qh_pointid(qh, vertex->point);
        ++k;
      }
      if (k != 4) continue;  // not a tetrahedron (cannot happen with Qt)
      tet_of[facet->id] = static_cast<int>(s.tets_.size());
      s.tets_.push_back(t);
    }
    s.neighbours_.assign(s.tets_.size(), {-1, -1, -1, -1});
    facetT *neighbor, **neighborp;
    FORALLfacets {
      const int t = facet->upperdelaunay ? -1 : tet_of[facet->id];
      if (t < 0) continue;
      FOREACHneighbor_(facet) {
        const int u = neighbor->upperdelaunay ? -1 : tet_of[neighbor->id];
        if (u < 0) continue;
        // The shared triangle is opposite the one vertex of t that u lacks.
        const auto& tv = s.tets_[t];
        const auto& uv = s.tets_[u];
        for (int i = 0; i < 4; ++i)
          if (std::find(uv.begin(), uv.end(), tv[i]) == uv.end()) s.neighbours_[t][i] = u;
      }
    }
  }
  if (!run.ok() || s.tets_.empty())
    throw InputError("the tip's point cloud spans no volume, so it has no boundary (qhull: " + run.error() + ")");

  s.radius_.resize(s.tets_.size());
  for (std::size_t t = 0; t < s.tets_.size(); ++t) {
    const auto& v = s.tets_[t];
    s.radius_[t] = circumradius(points[v[0]], points[v[1]], points[v[2]], points[v[3]]);
  }

  // The critical alpha 'one-region': add the tetrahedra in increasing circumradius (ties together)
  // until every vertex of the triangulation is covered and the solid is one face-connected region.
  std::vector<int> order(s.tets_.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return s.radius_[a] < s.radius_[b]; });
  std::vector<char> vertex_used(points.size(), 0), covered(points.size(), 0), added(s.tets_.size(), 0);
  std::int64_t n_vertices = 0, n_covered = 0, regions = 0;
  for (const auto& t : s.tets_)
    for (int v : t)
      if (!vertex_used[v]) vertex_used[v] = 1, ++n_vertices;
  Regions uf(s.tets_.size());
  s.critical_alpha_ = std::numeric_limits<double>::quiet_NaN();
  double largest_finite = 0.0;
  for (std::size_t k = 0; k < order.size();) {
    const double r = s.radius_[order[k]];
    if (!std::isfinite(r)) break;
    largest_finite = r;
    for (; k < order.size() && s.radius_[order[k]] == r; ++k) {
      const int t = order[k];
      added[t] = 1;
      ++regions;
      for (int i = 0; i < 4; ++i) {
        const int v = s.tets_[t][i];
        if (!covered[v]) covered[v] = 1, ++n_covered;
        const int u = s.neighbours_[t][i];
        if (u >= 0 && added[u] && uf.unite(t, u)) --regions;
      }
    }
    if (std::isnan(s.critical_alpha_) && n_covered == n_vertices && regions == 1) s.critical_alpha_ = r;
  }
  if (std::isnan(s.critical_alpha_)) s.critical_alpha_ = largest_finite;  // only the convex hull is one region

  // The spectrum from the critical alpha up (ascending, distinct, finite).
  for (int t : order) {
    const double r = s.radius_[t];
    if (!std::isfinite(r) || r < s.critical_alpha_) continue;
    if (s.spectrum_.empty() || s.spectrum_.back() != r) s.spectrum_.push_back(r);
  }
  s.spectrum_size_ = 0;
  for (std::size_t k = 0; k < order.size(); ++k) {
    const double r = s.radius_[order[k]];
    if (std::isfinite(r) && (k == 0 || r != s.radius_[order[k - 1]])) ++s.spectrum_size_;
  }
  s.alpha_ = s.alpha_for_shrink(shrink);
  return s;
}

double AlphaShape::alpha_for_shrink(double shrink) const {
  if (!(shrink >= 0.0 && shrink <= 1.0))
    throw InputError("the boundary's shrink factor must be within [0, 1], got " + std::to_string(shrink));
  if (spectrum_.empty()) return critical_alpha_;
  const auto m = static_cast<std::int64_t>(spectrum_.size());
  const auto idx = std::max<std::int64_t>(static_cast<std::int64_t>(std::ceil((1.0 - shrink) * m)), 1);
  return spectrum_[static_cast<std::size_t>(std::min(idx, m) - 1)];
}

std::int64_t AlphaShape::n_solid_tetrahedra() const {
  std::int64_t n = 0;
  for (std::size_t t = 0; t < tets_.size(); ++t) n += in_solid(t);
  return n;
}

std::int64_t AlphaShape::n_boundary_facets() const {
  std::int64_t n = 0;
  for (std::size_t t = 0; t < tets_.size(); ++t)
    if (in_solid(t))
      for (int u : neighbours_[t]) n += u < 0 || !in_solid(static_cast<std::size_t>(u));
  return n;
}

int AlphaShape::n_regions() const {
  Regions uf(tets_.size());
  int regions = 0;
  for (std::size_t t = 0; t < tets_.size(); ++t) {
    if (!in_solid(t)) continue;
    ++regions;
    for (int u : neighbours_[t])
      if (u >= 0 && static_cast<std::size_t>(u) < t && in_solid(static_cast<std::size_t>(u)) &&
          uf.unite(static_cast<int>(t), u))
        --regions;
  }
  return regions;
}

double AlphaShape::volume() const {
  double v = 0.0;
  for (std::size_t t = 0; t < tets_.size(); ++t) {
    if (!in_solid(t)) continue;
    const auto& i = tets_[t];
    const Eigen::Vector3d& a = points_[i[0]];
    v += std::abs((points_[i[1]] - a).dot((points_[i[2]] - a).cross(points_[i[3]] - a))) / 6.0;
  }
  return v;
}

namespace {
// Barycentric coordinates of p in the tetrahedron (a, b, c, d) are (1 - sum(l), l) with l = M^-1 (p - a).
bool in_tetrahedron(const Eigen::Matrix3d& inverse, const Eigen::Vector3d& a, const Eigen::Vector3d& p,
                    double tolerance) {
  const Eigen::Vector3d l = inverse * (p - a);
  return l.minCoeff() >= -tolerance && l.sum() <= 1.0 + tolerance;
}

bool edge_inverse(const std::vector<Eigen::Vector3d>& pts, const std::array<int, 4>& v, Eigen::Matrix3d& inverse) {
  Eigen::Matrix3d m;
  m.col(0) = pts[v[1]] - pts[v[0]];
  m.col(1) = pts[v[2]] - pts[v[0]];
  m.col(2) = pts[v[3]] - pts[v[0]];
  bool invertible = false;
  double det = 0.0;
  m.computeInverseAndDetWithCheck(inverse, det, invertible, 0.0);
  return invertible && std::isfinite(inverse.sum());
}
}  // namespace

bool AlphaShape::contains(const Eigen::Vector3d& p, double tolerance) const {
  Eigen::Matrix3d inv;
  for (std::size_t t = 0; t < tets_.size(); ++t)
    if (in_solid(t) && edge_inverse(points_, tets_[t], inv) && in_tetrahedron(inv, points_[tets_[t][0]], p, tolerance))
      return true;
  return false;
}

std::vector<std::int64_t> AlphaShape::voxels_inside(const VoxelGrid& grid) const {
  std::vector<std::int64_t> ids;
  const double h = grid.voxel;
  const int n = grid.n;
  Eigen::Matrix3d inv;
  for (std::size_t t = 0; t < tets_.size(); ++t) {
    if (!in_solid(t) || !edge_inverse(points_, tets_[t], inv)) continue;
    const auto& v = tets_[t];
    Eigen::Vector3d lo = points_[v[0]], hi = points_[v[0]];
    for (int k = 1; k < 4; ++k) lo = lo.cwiseMin(points_[v[k]]), hi = hi.cwiseMax(points_[v[k]]);
    // Voxel centres origin + (i + 1/2) h within [lo, hi] (one more on each side for rounding).
    int first[3], last[3];
    for (int d = 0; d < 3; ++d) {
      first[d] = std::max(0, static_cast<int>(std::ceil((lo[d] - grid.origin[d]) / h - 0.5)) - 1);
      last[d] = std::min(n - 1, static_cast<int>(std::floor((hi[d] - grid.origin[d]) / h - 0.5)) + 1);
    }
    for (int i = first[0]; i <= last[0]; ++i)
      for (int j = first[1]; j <= last[1]; ++j)
        for (int l = first[2]; l <= last[2]; ++l) {
          const std::int64_t k = (static_cast<std::int64_t>(i) * n + j) * n + l;
          if (in_tetrahedron(inv, points_[v[0]], grid.centre_of(k), 1e-12)) ids.push_back(k);
        }
  }
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  return ids;
}

}  // namespace snakehead
