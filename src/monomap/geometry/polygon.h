// 2D polygons in plane coordinates: the bounded extent of a plane segment.
#pragma once

#include <vector>

#include <Eigen/Core>

namespace monomap {

using Polygon2d = std::vector<Eigen::Vector2d>;

// Convex hull (Andrew's monotone chain), counter-clockwise, no repeated
// first vertex. Fewer than 3 distinct points give what there is.
Polygon2d ConvexHull(std::vector<Eigen::Vector2d> points);

// Signed area (> 0 for counter-clockwise).
double PolygonArea(const Polygon2d& polygon);

// Area centroid of a simple polygon; the mean of its vertices when its area
// is zero (fewer than 3 vertices, or collinear ones). Empty: (0, 0).
Eigen::Vector2d PolygonCentroid(const Polygon2d& polygon);

// Even-odd point-in-polygon test (works for non-convex simple polygons).
bool PointInPolygon(const Polygon2d& polygon, const Eigen::Vector2d& p);

// Distance from p to the polygon: 0 inside it, else to its nearest edge.
double DistanceToPolygon(const Polygon2d& polygon, const Eigen::Vector2d& p);

// Axis-aligned bounds of a polygon: min and max corners.
void PolygonBounds(const Polygon2d& polygon, Eigen::Vector2d* min,
                   Eigen::Vector2d* max);

}  // namespace monomap
