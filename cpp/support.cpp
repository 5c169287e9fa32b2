#include "snakehead/support.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>

#include "snakehead/model.hpp"

namespace snakehead {
namespace {

using Points = Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>;

double cross(const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}

// Distance from p to segment [a, b].
double segment_distance(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d e = b - a;
  const double len2 = e.squaredNorm();
  const double u = len2 > 0.0 ? std::clamp((p - a).dot(e) / len2, 0.0, 1.0) : 0.0;
  return (p - (a + u * e)).norm();
}

// Sample t's active points (of N, layout as hull_margins) into the first rows of `buffer`, their indices among
// the N into `index` (when given); returns how many.
long gather_active(const double* points, const unsigned char* active, long t, long N, Points& buffer,
                   std::vector<int>* index) {
  long m = 0;
  for (long i = 0; i < N; ++i) {
    if (!active[t * N + i]) continue;
    buffer(m, 0) = points[(t * N + i) * 2];
    buffer(m, 1) = points[(t * N + i) * 2 + 1];
    if (index != nullptr) (*index)[static_cast<std::size_t>(m)] = static_cast<int>(i);
    ++m;
  }
  return m;
}

}  // namespace

std::vector<int> convex_hull(const Eigen::Ref<const Points>& points) {
  HullWork work;
  std::vector<int> hull;
  convex_hull_into(points, work, hull);
  return hull;
}

namespace {

// Drops from `order` (sorted by x, then y) each point within eps of a point kept before it that is not the one just
// before it: round-off twins such as x = 0.1 and 0.10000000000000003 sort apart when points with x = 0.1 and a
// larger y lie between them, and the chain would pop the corners between them for the later twin, then drop it as a
// duplicate (a triangle came out as a segment). Twins next to each other are left to the chain's own test.
void drop_distant_twins(const Eigen::Ref<const Points>& points, double eps, std::vector<int>& order) {
  std::size_t kept = 0;
  for (std::size_t k = 0; k < order.size(); ++k) {
    const int i = order[k];
    bool twin = false;
    for (std::size_t m = kept; m-- > 1 && !twin;) {  // back over the kept points within eps in x, but the last
      const int j = order[m - 1];
      if (points(i, 0) - points(j, 0) > eps) break;
      twin = std::abs(points(i, 1) - points(j, 1)) <= eps;
    }
    if (!twin) order[kept++] = i;
  }
  order.resize(kept);
}

}  // namespace

void convex_hull_into(const Eigen::Ref<const Points>& points, HullWork& work, std::vector<int>& hull) {
  const int n = static_cast<int>(points.rows());
  std::vector<int>& order = work.order;
  order.resize(static_cast<std::size_t>(n));
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int i, int j) {
    return points(i, 0) < points(j, 0) || (points(i, 0) == points(j, 0) && points(i, 1) < points(j, 1));
  });
  double scale = 1.0;
  for (int i = 0; i < n; ++i) scale = std::max({scale, std::abs(points(i, 0)), std::abs(points(i, 1))});
  const double eps = 1e-12 * scale;
  drop_distant_twins(points, eps, order);
  auto half = [&](auto begin, auto end, std::vector<int>& out) {
    out.clear();
    for (auto it = begin; it != end; ++it) {
      const int i = *it;
      const Eigen::Vector2d p = points.row(i).transpose();
      // pop while the turn is not strictly left: a sine of the turn angle below 1e-9 counts as straight
      while (out.size() >= 2) {
        const Eigen::Vector2d o = points.row(out[out.size() - 2]).transpose(), a = points.row(out.back()).transpose();
        if (cross(o, a, p) > 1e-9 * (a - o).norm() * (p - a).norm()) break;
        out.pop_back();
      }
      if (!out.empty() && (points.row(out.back()).transpose() - p).cwiseAbs().maxCoeff() <= eps) continue;
      out.push_back(i);
    }
  };
  const std::vector<int>& lower = work.lower;
  const std::vector<int>& upper = work.upper;
  half(order.begin(), order.end(), work.lower);
  half(order.rbegin(), order.rend(), work.upper);
  hull.clear();
  if (lower.size() < 2) {
    hull.assign(lower.begin(), lower.end());
    return;
  }
  hull.assign(lower.begin(), lower.end() - 1);
  hull.insert(hull.end(), upper.begin(), upper.end() - 1);
  if (hull.size() < 2) hull.assign(lower.begin(), lower.begin() + std::min<std::size_t>(2, lower.size()));
}

double convex_margin(const double* vertices, long k, const Eigen::Vector2d& xy) {
  const auto vertex = [vertices](long i) { return Eigen::Vector2d(vertices[2 * i], vertices[2 * i + 1]); };
  if (k == 0) return -std::numeric_limits<double>::infinity();
  if (k == 1) return -(xy - vertex(0)).norm();
  if (k == 2) return -segment_distance(xy, vertex(0), vertex(1));
  bool inside = true;
  double best = std::numeric_limits<double>::infinity();
  for (long i = 0; i < k; ++i) {
    const Eigen::Vector2d a = vertex(i), b = vertex((i + 1) % k);
    const Eigen::Vector2d e = b - a;
    if (e.x() * (xy.y() - a.y()) - e.y() * (xy.x() - a.x()) < 0.0) inside = false;  // right of a ccw edge
    best = std::min(best, segment_distance(xy, a, b));
  }
  return inside ? best : -best;
}

double hull_margin(const Eigen::Ref<const Points>& points, const Eigen::Vector2d& xy) {
  if (points.rows() == 0) return -std::numeric_limits<double>::infinity();
  if (!xy.allFinite() || !points.allFinite()) throw InputError("hull_margin: points and xy must be finite");
  const std::vector<int> h = convex_hull(points);
  Points vertices(static_cast<Eigen::Index>(h.size()), 2);
  for (std::size_t v = 0; v < h.size(); ++v) vertices.row(static_cast<Eigen::Index>(v)) = points.row(h[v]);
  return convex_margin(vertices.data(), vertices.rows(), xy);
}

std::vector<double> hull_margins(const double* points, const unsigned char* active, const double* xy, long T,
                                 long N) {
  if (T < 0 || N < 0) throw InputError("hull_margins: negative sizes");
  std::vector<double> out(static_cast<std::size_t>(T));
  Points buffer(N, 2);
  for (long t = 0; t < T; ++t) {
    const long m = gather_active(points, active, t, N, buffer, nullptr);
    out[static_cast<std::size_t>(t)] = hull_margin(buffer.topRows(m), Eigen::Vector2d(xy[2 * t], xy[2 * t + 1]));
  }
  return out;
}

void convex_hulls(const double* points, const unsigned char* active, long T, long N, int* vertex, int* count) {
  if (T < 0 || N < 0) throw InputError("convex_hulls: negative sizes");
  Points buffer(N, 2);
  std::vector<int> index(static_cast<std::size_t>(N));
  for (long t = 0; t < T; ++t) {
    const long m = gather_active(points, active, t, N, buffer, &index);
    if (!buffer.topRows(m).allFinite()) throw InputError("convex_hulls: points must be finite");
    const std::vector<int> h = convex_hull(buffer.topRows(m));
    int* row = vertex + t * N;
    std::fill(row, row + N, -1);
    for (std::size_t k = 0; k < h.size(); ++k) row[k] = index[static_cast<std::size_t>(h[k])];
    count[t] = static_cast<int>(h.size());
  }
}

}  // namespace snakehead
