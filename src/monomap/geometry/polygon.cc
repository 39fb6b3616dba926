#include "monomap/geometry/polygon.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace monomap {

namespace {
double Cross(const Eigen::Vector2d& o, const Eigen::Vector2d& a,
             const Eigen::Vector2d& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}
}  // namespace

Polygon2d ConvexHull(std::vector<Eigen::Vector2d> pts) {
  std::sort(pts.begin(), pts.end(), [](const auto& a, const auto& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  if (pts.size() < 3) return pts;
  Polygon2d hull(2 * pts.size());
  size_t k = 0;
  for (size_t i = 0; i < pts.size(); ++i) {
    while (k >= 2 && Cross(hull[k - 2], hull[k - 1], pts[i]) <= 0) --k;
    hull[k++] = pts[i];
  }
  for (size_t i = pts.size() - 1, t = k + 1; i > 0; --i) {
    while (k >= t && Cross(hull[k - 2], hull[k - 1], pts[i - 1]) <= 0) --k;
    hull[k++] = pts[i - 1];
  }
  hull.resize(k - 1);
  return hull;
}

double PolygonArea(const Polygon2d& polygon) {
  double a = 0.0;
  for (size_t i = 0, n = polygon.size(); i < n; ++i) {
    const auto& p = polygon[i];
    const auto& q = polygon[(i + 1) % n];
    a += p.x() * q.y() - q.x() * p.y();
  }
  return 0.5 * a;
}

Eigen::Vector2d PolygonCentroid(const Polygon2d& polygon) {
  if (polygon.empty()) return Eigen::Vector2d::Zero();
  // Relative to the first vertex, so far-off coordinates lose no precision.
  const Eigen::Vector2d o = polygon.front();
  double twice_area = 0.0;
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (size_t i = 0, n = polygon.size(); i < n; ++i) {
    const Eigen::Vector2d p = polygon[i] - o;
    const Eigen::Vector2d q = polygon[(i + 1) % n] - o;
    const double cross = p.x() * q.y() - q.x() * p.y();
    twice_area += cross;
    sum += cross * (p + q);
  }
  if (std::abs(twice_area) > 1e-12 * (1.0 + sum.norm())) {
    return o + sum / (3.0 * twice_area);
  }
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& v : polygon) mean += v;
  return mean / static_cast<double>(polygon.size());
}

bool PointInPolygon(const Polygon2d& polygon, const Eigen::Vector2d& p) {
  bool inside = false;
  for (size_t i = 0, n = polygon.size(), j = n - 1; i < n; j = i++) {
    const auto& a = polygon[i];
    const auto& b = polygon[j];
    if ((a.y() > p.y()) != (b.y() > p.y()) &&
        p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x()) {
      inside = !inside;
    }
  }
  return inside;
}

double DistanceToPolygon(const Polygon2d& polygon, const Eigen::Vector2d& p) {
  if (polygon.empty()) return std::numeric_limits<double>::infinity();
  if (polygon.size() >= 3 && PointInPolygon(polygon, p)) return 0.0;
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < polygon.size(); ++i) {
    const Eigen::Vector2d& a = polygon[i];
    const Eigen::Vector2d& b = polygon[(i + 1) % polygon.size()];
    const Eigen::Vector2d ab = b - a;
    const double len2 = ab.squaredNorm();
    const double t =
        len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
    best = std::min(best, (a + t * ab - p).norm());
  }
  return best;
}

void PolygonBounds(const Polygon2d& polygon, Eigen::Vector2d* min,
                   Eigen::Vector2d* max) {
  *min = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  *max = -*min;
  for (const auto& p : polygon) {
    *min = min->cwiseMin(p);
    *max = max->cwiseMax(p);
  }
}

}  // namespace monomap
