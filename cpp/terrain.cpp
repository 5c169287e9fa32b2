#include "snakehead/terrain.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <string>
#include <unordered_map>
#include <utility>

#include "snakehead/limits.hpp"
#include "snakehead/model.hpp"
#include "snakehead/parallel_for.hpp"

namespace snakehead {

using Vertices = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
using Faces = std::vector<std::array<int, 3>>;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr long kGrain = 256;     // points per thread at least: a query costs about a microsecond
constexpr int kLeafSize = 4;     // triangles per leaf of the tree

// Where on a triangle its closest point to a point lies: its inside, a vertex (0, 1, 2) or an edge (0: ab,
// 1: bc, 2: ca).
enum class Feature { Face, Vertex, Edge };
struct TriangleHit {
  Eigen::Vector3d point;
  Feature feature = Feature::Face;
  int index = 0;
};

// The closest point of triangle abc to p (Ericson, Real-Time Collision Detection, 5.1.5), and its feature.
TriangleHit closest_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return {a, Feature::Vertex, 0};
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return {b, Feature::Vertex, 1};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return {a + ab * (d1 / (d1 - d3)), Feature::Edge, 0};
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return {c, Feature::Vertex, 2};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return {a + ac * (d2 / (d2 - d6)), Feature::Edge, 2};
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0)
    return {b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))), Feature::Edge, 1};
  const double denom = 1.0 / (va + vb + vc);
  return {a + ab * (vb * denom) + ac * (vc * denom), Feature::Face, 0};
}

// The closest points of segments p1 q1 and p2 q2 (Ericson 5.1.9): the squared distance between them.
double segment_segment_distance2(const Eigen::Vector3d& p1, const Eigen::Vector3d& q1, const Eigen::Vector3d& p2,
                                 const Eigen::Vector3d& q2) {
  const Eigen::Vector3d d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  double s = 0.0, t = 0.0;
  if (a <= 0.0 && e <= 0.0) return r.squaredNorm();
  if (a <= 0.0) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r);
    if (e <= 0.0) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2), denom = a * e - b * b;
      s = denom > 0.0 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0.0) {
        t = 0.0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1.0) {
        t = 1.0;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  return ((p1 + d1 * s) - (p2 + d2 * t)).squaredNorm();
}

// Whether segment p q meets triangle abc (Moller-Trumbore, with the segment's parameter in [0, 1]).
bool segment_meets_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& a,
                            const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d d = q - p, e1 = b - a, e2 = c - a, h = d.cross(e2);
  const double det = e1.dot(h);
  if (std::abs(det) < 1e-300) return false;  // parallel: a touch is found by the edge distances
  const Eigen::Vector3d s = p - a;
  const double u = s.dot(h) / det;
  if (u < 0.0 || u > 1.0) return false;
  const Eigen::Vector3d qv = s.cross(e1);
  const double v = d.dot(qv) / det;
  if (v < 0.0 || u + v > 1.0) return false;
  const double t = e2.dot(qv) / det;
  return t >= 0.0 && t <= 1.0;
}

struct Box {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(kInf), hi = Eigen::Vector3d::Constant(-kInf);
  void grow(const Eigen::Vector3d& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  void grow(const Box& b) {
    lo = lo.cwiseMin(b.lo);
    hi = hi.cwiseMax(b.hi);
  }
  double distance2(const Eigen::Vector3d& p) const {
    return (lo - p).cwiseMax(p - hi).cwiseMax(0.0).squaredNorm();
  }
  double distance2(const Box& b) const { return (lo - b.hi).cwiseMax(b.lo - hi).cwiseMax(0.0).squaredNorm(); }
  bool holds_xy(double x, double y) const { return x >= lo.x() && x <= hi.x() && y >= lo.y() && y <= hi.y(); }
};

// A node of the tree: a leaf (left < 0) holds order_[first, first + count); an inner node's children are `left`
// and `right`.
struct Node {
  Box box;
  int left = -1, right = -1, first = 0, count = 0;
};

}  // namespace

// The triangles of a heightfield or a mesh, their normals and pseudonormals, and a bounding-box tree over them.
class TerrainSurface {
 public:
  TerrainSurface(Vertices v, Faces f);

  struct Closest {
    double distance2 = kInf;
    int face = -1;
    TriangleHit hit;
  };
  // The closest point within sqrt(bound2) (an upper bound of the distance: the search starts there).
  Closest closest(const Eigen::Vector3d& p, double bound2 = kInf) const;
  double signed_distance(const Eigen::Vector3d& p) const;
  // The highest point of the surface on the vertical line through (x, y): its z and face (-1: none).
  std::pair<double, int> highest(double x, double y) const;
  // The squared distance of segment p q to the surface (0 when it meets it); bound2: an upper bound of it.
  double segment_distance2(const Eigen::Vector3d& p, const Eigen::Vector3d& q, double bound2 = kInf) const;

  Vertices vertices;
  Faces faces;
  std::vector<Eigen::Vector3d> face_normals;  // unit, by the right-hand rule of a, b, c

 private:
  Eigen::Vector3d corner(int face, int k) const { return vertices.row(faces[face][k]).transpose(); }
  void make_pseudonormals();
  int build(int first, int count);
  Eigen::Vector3d pseudonormal(const Closest& c) const;

  std::vector<Eigen::Vector3d> vertex_normals_;               // angle-weighted
  std::vector<std::array<Eigen::Vector3d, 3>> edge_normals_;  // per face: ab, bc, ca; sum of the adjacent faces'
  std::vector<int> order_;
  std::vector<Box> face_boxes_;
  std::vector<Node> nodes_;
};

TerrainSurface::TerrainSurface(Vertices v, Faces f) : vertices(std::move(v)), faces(std::move(f)) {
  face_normals.resize(faces.size());
  face_boxes_.resize(faces.size());
  for (std::size_t i = 0; i < faces.size(); ++i) {
    const int fi = static_cast<int>(i);
    const Eigen::Vector3d n = (corner(fi, 1) - corner(fi, 0)).cross(corner(fi, 2) - corner(fi, 0));
    if (!(n.norm() > 0.0)) throw InputError("Terrain: triangle " + std::to_string(i) + " has no area");
    face_normals[i] = n.normalized();
    for (int k = 0; k < 3; ++k) face_boxes_[i].grow(corner(fi, k));
  }
  make_pseudonormals();
  order_.resize(faces.size());
  std::iota(order_.begin(), order_.end(), 0);
  nodes_.reserve(2 * faces.size() / kLeafSize + 2);
  build(0, static_cast<int>(faces.size()));
}

// Each vertex's first copy: vertices at the same place are one (an STL file repeats every vertex per triangle), so
// that the triangles around a vertex or an edge share its pseudonormal.
static std::vector<int> welded(const Vertices& v) {
  std::vector<int> order(static_cast<std::size_t>(v.rows())), first(order.size());
  std::iota(order.begin(), order.end(), 0);
  const auto row = [&](int i) { return std::array<double, 3>{v(i, 0), v(i, 1), v(i, 2)}; };
  std::sort(order.begin(), order.end(), [&](int a, int b) { return row(a) < row(b) || (row(a) == row(b) && a < b); });
  for (std::size_t k = 0; k < order.size(); ++k)
    first[static_cast<std::size_t>(order[k])] =
        k > 0 && row(order[k]) == row(order[k - 1]) ? first[static_cast<std::size_t>(order[k - 1])] : order[k];
  return first;
}

void TerrainSurface::make_pseudonormals() {
  vertex_normals_.assign(static_cast<std::size_t>(vertices.rows()), Eigen::Vector3d::Zero());
  const std::vector<int> same = welded(vertices);
  std::unordered_map<std::uint64_t, Eigen::Vector3d> edges;
  const auto key = [&](int u, int w) {
    u = same[static_cast<std::size_t>(u)];
    w = same[static_cast<std::size_t>(w)];
    return (static_cast<std::uint64_t>(std::min(u, w)) << 32) | static_cast<std::uint32_t>(std::max(u, w));
  };
  for (std::size_t i = 0; i < faces.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      const int fi = static_cast<int>(i);
      const Eigen::Vector3d e1 = (corner(fi, (k + 1) % 3) - corner(fi, k)).normalized();
      const Eigen::Vector3d e2 = (corner(fi, (k + 2) % 3) - corner(fi, k)).normalized();
      const double angle = std::acos(std::clamp(e1.dot(e2), -1.0, 1.0));
      vertex_normals_[static_cast<std::size_t>(same[static_cast<std::size_t>(faces[i][k])])] += angle * face_normals[i];
      auto [it, fresh] = edges.try_emplace(key(faces[i][k], faces[i][(k + 1) % 3]), Eigen::Vector3d::Zero());
      it->second += face_normals[i];
    }
  }
  edge_normals_.resize(faces.size());
  for (std::size_t i = 0; i < faces.size(); ++i)
    for (int k = 0; k < 3; ++k) edge_normals_[i][k] = edges.at(key(faces[i][k], faces[i][(k + 1) % 3]));
  for (std::size_t i = 0; i < same.size(); ++i) vertex_normals_[i] = vertex_normals_[static_cast<std::size_t>(same[i])];
}

// Builds the subtree over order_[first, first + count): split at the median of the longest axis of the triangles'
// centres. Returns the node's index.
int TerrainSurface::build(int first, int count) {
  const int index = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  Box box, centres;
  for (int k = first; k < first + count; ++k) {
    const Box& b = face_boxes_[static_cast<std::size_t>(order_[k])];
    box.grow(b);
    centres.grow(0.5 * (b.lo + b.hi));
  }
  nodes_[index].box = box;
  if (count <= kLeafSize) {
    nodes_[index].first = first;
    nodes_[index].count = count;
    return index;
  }
  int axis = 0;
  (centres.hi - centres.lo).maxCoeff(&axis);
  const auto centre = [&](int f) { return face_boxes_[f].lo(axis) + face_boxes_[f].hi(axis); };
  const int half = count / 2;
  std::nth_element(order_.begin() + first, order_.begin() + first + half, order_.begin() + first + count,
                   [&](int x, int y) { return centre(x) < centre(y); });
  const int left = build(first, half);
  const int right = build(first + half, count - half);
  nodes_[index].left = left;
  nodes_[index].right = right;
  return index;
}

TerrainSurface::Closest TerrainSurface::closest(const Eigen::Vector3d& p, double bound2) const {
  Closest best;
  best.distance2 = bound2;
  int stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if (node.box.distance2(p) >= best.distance2) continue;
    if (node.left < 0) {
      for (int k = node.first; k < node.first + node.count; ++k) {
        const int f = order_[k];
        const TriangleHit hit = closest_on_triangle(p, corner(f, 0), corner(f, 1), corner(f, 2));
        const double d2 = (hit.point - p).squaredNorm();
        if (d2 < best.distance2) best = {d2, f, hit};
      }
      continue;
    }
    const double dl = nodes_[node.left].box.distance2(p), dr = nodes_[node.right].box.distance2(p);
    const bool left_first = dl <= dr;  // the nearer child is popped first
    stack[top++] = left_first ? node.right : node.left;
    stack[top++] = left_first ? node.left : node.right;
  }
  return best;
}

Eigen::Vector3d TerrainSurface::pseudonormal(const Closest& c) const {
  const std::size_t f = static_cast<std::size_t>(c.face);
  switch (c.hit.feature) {
    case Feature::Face: return face_normals[f];
    case Feature::Edge: return edge_normals_[f][c.hit.index];
    case Feature::Vertex: return vertex_normals_[static_cast<std::size_t>(faces[f][c.hit.index])];
  }
  return face_normals[f];
}

double TerrainSurface::signed_distance(const Eigen::Vector3d& p) const {
  if (!p.allFinite()) return kNaN;
  // The surface point straight above or below bounds the distance (a little over it, so that it is found).
  const double z = highest(p.x(), p.y()).first;
  const double bound2 = std::isnan(z) ? kInf : (p.z() - z) * (p.z() - z) * (1.0 + 1e-9) + 1e-300;
  Closest c = closest(p, bound2);
  if (c.face < 0) c = closest(p);  // (round-off kept the bound below every triangle)
  const double d = std::sqrt(c.distance2);
  return (p - c.hit.point).dot(pseudonormal(c)) >= 0.0 ? d : -d;
}

std::pair<double, int> TerrainSurface::highest(double x, double y) const {
  double best = -kInf;
  int face = -1;
  int stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if (!node.box.holds_xy(x, y) || node.box.hi.z() <= best) continue;
    if (node.left >= 0) {
      stack[top++] = node.left;
      stack[top++] = node.right;
      continue;
    }
    for (int k = node.first; k < node.first + node.count; ++k) {
      const int f = order_[k];
      const Eigen::Vector3d a = corner(f, 0), b = corner(f, 1), c = corner(f, 2);
      // Barycentric coordinates of (x, y) in the triangle's projection (none for a vertical triangle).
      const double det = (b.x() - a.x()) * (c.y() - a.y()) - (c.x() - a.x()) * (b.y() - a.y());
      if (det == 0.0) continue;
      const double u = ((x - a.x()) * (c.y() - a.y()) - (c.x() - a.x()) * (y - a.y())) / det;
      const double v = ((b.x() - a.x()) * (y - a.y()) - (x - a.x()) * (b.y() - a.y())) / det;
      if (u < 0.0 || v < 0.0 || u + v > 1.0) continue;
      const double z = a.z() + u * (b.z() - a.z()) + v * (c.z() - a.z());
      if (z > best) {
        best = z;
        face = f;
      }
    }
  }
  return {face < 0 ? kNaN : best, face};
}

double TerrainSurface::segment_distance2(const Eigen::Vector3d& p, const Eigen::Vector3d& q, double bound2) const {
  Box segment;
  segment.grow(p);
  segment.grow(q);
  double best = bound2;
  int stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0 && best > 0.0) {
    const Node& node = nodes_[stack[--top]];
    if (node.box.distance2(segment) >= best) continue;
    if (node.left >= 0) {
      const bool left_first = nodes_[node.left].box.distance2(segment) <= nodes_[node.right].box.distance2(segment);
      stack[top++] = left_first ? node.right : node.left;
      stack[top++] = left_first ? node.left : node.right;
      continue;
    }
    for (int k = node.first; k < node.first + node.count; ++k) {
      const int f = order_[k];
      const Eigen::Vector3d a = corner(f, 0), b = corner(f, 1), c = corner(f, 2);
      if (segment_meets_triangle(p, q, a, b, c)) return 0.0;
      best = std::min({best, (closest_on_triangle(p, a, b, c).point - p).squaredNorm(),
                       (closest_on_triangle(q, a, b, c).point - q).squaredNorm(),
                       segment_segment_distance2(p, q, a, b), segment_segment_distance2(p, q, b, c),
                       segment_segment_distance2(p, q, c, a)});
    }
  }
  return best;
}

namespace {

// --- construction checks -------------------------------------------------------------------------------------

void check_grid(const HeightfieldGrid& g) {
  if (g.nx < 2 || g.ny < 2)
    throw InputError("Terrain: a heightfield needs at least 2 x 2 heights, got " + std::to_string(g.nx) + " x " +
                     std::to_string(g.ny));
  if ((g.nx - 1) > limits::kMaxTerrainCells / (g.ny - 1))
    throw InputError("Terrain: a heightfield of " + std::to_string(g.nx) + " x " + std::to_string(g.ny) +
                     " heights has more than " + std::to_string(limits::kMaxTerrainCells) + " cells");
  if (static_cast<long>(g.heights.size()) != g.nx * g.ny) throw InputError("Terrain: heights must hold nx * ny values");
  for (double h : g.heights)
    if (!std::isfinite(h)) throw InputError("Terrain: heights must be finite");
  if (!(std::isfinite(g.size_x) && std::isfinite(g.size_y) && g.size_x > 0.0 && g.size_y > 0.0))
    throw InputError("Terrain: a heightfield's extent must be finite and > 0");
  if (!g.origin.allFinite()) throw InputError("Terrain: a heightfield's origin must be finite");
}

// The grid's points (nx * ny, index i * ny + j) and its triangles, two per cell split along (i, j) - (i+1, j+1),
// counter-clockwise seen from above.
std::pair<Vertices, Faces> grid_triangles(const HeightfieldGrid& g) {
  Vertices v(g.nx * g.ny, 3);
  for (long i = 0; i < g.nx; ++i)
    for (long j = 0; j < g.ny; ++j)
      v.row(i * g.ny + j) << g.origin.x() + static_cast<double>(i) * g.size_x / static_cast<double>(g.nx - 1),
          g.origin.y() + static_cast<double>(j) * g.size_y / static_cast<double>(g.ny - 1),
          g.origin.z() + g.heights[static_cast<std::size_t>(i * g.ny + j)];
  Faces f;
  f.reserve(static_cast<std::size_t>(2 * (g.nx - 1) * (g.ny - 1)));
  for (long i = 0; i + 1 < g.nx; ++i)
    for (long j = 0; j + 1 < g.ny; ++j) {
      const int p00 = static_cast<int>(i * g.ny + j), p10 = static_cast<int>((i + 1) * g.ny + j);
      f.push_back({p00, p10, p10 + 1});
      f.push_back({p00, p10 + 1, p00 + 1});
    }
  return {std::move(v), std::move(f)};
}

// A heightfield's cell under (x, y) and the point's place in it: (u, v) in [0, 1]^2; false outside the extent.
struct Cell {
  long i = 0, j = 0;
  double u = 0.0, v = 0.0;
};
bool cell_of(const HeightfieldGrid& g, double x, double y, Cell& c) {
  const double s = (x - g.origin.x()) / g.size_x * static_cast<double>(g.nx - 1);
  const double t = (y - g.origin.y()) / g.size_y * static_cast<double>(g.ny - 1);
  if (!(s >= 0.0 && s <= static_cast<double>(g.nx - 1) && t >= 0.0 && t <= static_cast<double>(g.ny - 1))) return false;
  c.i = std::min(static_cast<long>(s), g.nx - 2);
  c.j = std::min(static_cast<long>(t), g.ny - 2);
  c.u = s - static_cast<double>(c.i);
  c.v = t - static_cast<double>(c.j);
  return true;
}

// The heights at a cell's corners: z00 at (i, j), z10 at (i+1, j), z01, z11.
struct Corners {
  double z00, z10, z01, z11;
};
Corners corners_of(const HeightfieldGrid& g, const Cell& c) {
  const auto h = [&](long i, long j) { return g.heights[static_cast<std::size_t>(i * g.ny + j)]; };
  return {h(c.i, c.j), h(c.i + 1, c.j), h(c.i, c.j + 1), h(c.i + 1, c.j + 1)};
}

// The slopes dz/dx, dz/dy of the triangle of the cell holding (u, v): u >= v the one below the diagonal.
Eigen::Vector2d cell_slopes(const HeightfieldGrid& g, const Cell& c) {
  const Corners z = corners_of(g, c);
  const double dx = g.size_x / static_cast<double>(g.nx - 1), dy = g.size_y / static_cast<double>(g.ny - 1);
  if (c.u >= c.v) return {(z.z10 - z.z00) / dx, (z.z11 - z.z10) / dy};
  return {(z.z11 - z.z01) / dx, (z.z01 - z.z00) / dy};
}

double grid_height(const HeightfieldGrid& g, double x, double y) {
  Cell c;
  if (!cell_of(g, x, y, c)) return kNaN;
  const Corners z = corners_of(g, c);
  const double h = c.u >= c.v ? z.z00 + c.u * (z.z10 - z.z00) + c.v * (z.z11 - z.z10)
                              : z.z00 + c.v * (z.z01 - z.z00) + c.u * (z.z11 - z.z01);
  return g.origin.z() + h;
}

Eigen::Vector3d upward(const Eigen::Vector3d& n) { return n.z() < 0.0 ? Eigen::Vector3d(-n) : n; }

Eigen::Vector3d nan3() { return Eigen::Vector3d::Constant(kNaN); }

}  // namespace

// --- construction --------------------------------------------------------------------------------------------

Terrain Terrain::plane(const Eigen::Vector3d& normal, const Eigen::Vector3d& point) {
  if (!normal.allFinite() || !(normal.norm() > 0.0)) throw InputError("Terrain: a plane's normal must be finite and non-zero");
  if (!point.allFinite()) throw InputError("Terrain: a plane's point must be finite");
  const Eigen::Vector3d n = normal.normalized();
  if (!(n.z() > 0.0)) throw InputError("Terrain: a plane's normal must point up (n_z > 0): a ground has a height");
  Terrain t;
  t.kind_ = TerrainKind::Plane;
  t.normal_ = n;
  t.point_ = point;
  return t;
}

Terrain Terrain::heightfield(HeightfieldGrid grid) {
  check_grid(grid);
  auto [v, f] = grid_triangles(grid);
  Terrain t;
  t.kind_ = TerrainKind::Heightfield;
  t.surface_ = std::make_shared<const TerrainSurface>(std::move(v), std::move(f));
  t.grid_ = std::move(grid);
  return t;
}

Terrain Terrain::mesh(Vertices vertices, Faces faces) {
  if (faces.empty()) throw InputError("Terrain: a mesh needs at least one triangle");
  if (static_cast<long>(faces.size()) > limits::kMaxTerrainTriangles)
    throw InputError("Terrain: a mesh of " + std::to_string(faces.size()) + " triangles; at most " +
                     std::to_string(limits::kMaxTerrainTriangles));
  if (!vertices.allFinite()) throw InputError("Terrain: a mesh's vertices must be finite");
  for (const auto& face : faces)
    for (int k : face)
      if (k < 0 || k >= vertices.rows()) throw InputError("Terrain: a triangle's index is outside the vertices");
  Terrain t;
  t.kind_ = TerrainKind::Mesh;
  t.surface_ = std::make_shared<const TerrainSurface>(std::move(vertices), std::move(faces));
  return t;
}

const Vertices& Terrain::vertices() const {
  static const Vertices none(0, 3);
  return surface_ ? surface_->vertices : none;
}

const Faces& Terrain::faces() const {
  static const Faces none;
  return surface_ ? surface_->faces : none;
}

// --- queries -------------------------------------------------------------------------------------------------

void Terrain::height(const double* xy, long n, double* out) const {
  parallel_for(n, kGrain, [&](long begin, long end) {
    for (long k = begin; k < end; ++k) {
      const double x = xy[2 * k], y = xy[2 * k + 1];
      if (kind_ == TerrainKind::Plane)
        out[k] = point_.z() - (normal_.x() * (x - point_.x()) + normal_.y() * (y - point_.y())) / normal_.z();
      else if (kind_ == TerrainKind::Heightfield)
        out[k] = grid_height(grid_, x, y);
      else
        out[k] = std::isfinite(x) && std::isfinite(y) ? surface_->highest(x, y).first : kNaN;
    }
  });
}

void Terrain::normal(const double* xy, long n, double* out) const {
  parallel_for(n, kGrain, [&](long begin, long end) {
    for (long k = begin; k < end; ++k) {
      const double x = xy[2 * k], y = xy[2 * k + 1];
      Eigen::Vector3d m = nan3();
      if (kind_ == TerrainKind::Plane) {
        if (std::isfinite(x) && std::isfinite(y)) m = normal_;
      } else if (kind_ == TerrainKind::Heightfield) {
        Cell c;
        if (cell_of(grid_, x, y, c)) {
          const Eigen::Vector2d slope = cell_slopes(grid_, c);
          m = Eigen::Vector3d(-slope.x(), -slope.y(), 1.0).normalized();
        }
      } else if (std::isfinite(x) && std::isfinite(y)) {
        const int face = surface_->highest(x, y).second;
        if (face >= 0) m = upward(surface_->face_normals[static_cast<std::size_t>(face)]);
      }
      Eigen::Map<Eigen::Vector3d>(out + 3 * k) = m;
    }
  });
}

void Terrain::signed_distance(const double* points, long n, double* out) const {
  parallel_for(n, kGrain, [&](long begin, long end) {
    for (long k = begin; k < end; ++k) {
      const Eigen::Vector3d p = Eigen::Map<const Eigen::Vector3d>(points + 3 * k);
      if (kind_ == TerrainKind::Plane) {
        out[k] = normal_.dot(p - point_);
        continue;
      }
      double d = surface_->signed_distance(p);
      if (kind_ == TerrainKind::Heightfield) {
        const double h = grid_height(grid_, p.x(), p.y());
        if (std::isfinite(h)) d = p.z() >= h ? std::abs(d) : -std::abs(d);
      }
      out[k] = d;
    }
  });
}

void Terrain::sphere_clearance(const double* centres, const double* radii, long n, double* out) const {
  signed_distance(centres, n, out);
  for (long k = 0; k < n; ++k) out[k] -= radii[k];
}

void Terrain::capsule_clearance(const double* a, const double* b, const double* radii, long n, double* out) const {
  std::vector<double> ends(static_cast<std::size_t>(2 * n));
  signed_distance(a, n, ends.data());
  signed_distance(b, n, ends.data() + n);
  parallel_for(n, kGrain, [&](long begin, long end) {
    for (long k = begin; k < end; ++k) {
      const double da = ends[static_cast<std::size_t>(k)], db = ends[static_cast<std::size_t>(n + k)];
      double d = std::isnan(da) || std::isnan(db) ? kNaN : std::min(da, db);
      if (kind_ != TerrainKind::Plane && d > 0.0) {
        const Eigen::Vector3d p = Eigen::Map<const Eigen::Vector3d>(a + 3 * k);
        const Eigen::Vector3d q = Eigen::Map<const Eigen::Vector3d>(b + 3 * k);
        d = std::min(d, std::sqrt(surface_->segment_distance2(p, q, d * d * (1.0 + 1e-9))));
      }
      out[k] = d - radii[k];
    }
  });
}

}  // namespace snakehead
