// Test helper: a navigation grid against true planes (a simulated world's
// or its structure/ map): distances of occupied cells to the true walls and
// obstacles, coverage of the true wall length, free floor.
#pragma once

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "monomap/geometry/polygon.h"
#include "monomap/io/nav_grid_export.h"

namespace monomap {

using Eigen::Vector2d;

// The obstacles a grid should show, straight from the world's planes:
// vertical rectangles reaching into the band as xy segments, horizontal
// planes inside the band as xy polygons.
struct NavGridTruthGeometry {
  std::vector<std::pair<Vector2d, Vector2d>> segments;
  std::vector<Polygon2d> areas;
  std::vector<Polygon2d> floors;  // horizontal planes below the band

  double FloorDistance(const Vector2d& p) const {
    double d = INFINITY;
    for (const Polygon2d& f : floors) d = std::min(d, DistanceToPolygon(f, p));
    return d;
  }
  double Distance(const Vector2d& p) const {
    double d = INFINITY;
    for (const auto& [a, b] : segments) {
      const double t =
          std::clamp((p - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
      d = std::min(d, (a + t * (b - a) - p).norm());
    }
    for (const Polygon2d& area : areas)
      d = std::min(d, DistanceToPolygon(area, p));
    return d;
  }
};

// The xy segments where the horizontal line at height z crosses a
// vertical plane's polygon (even-odd over the polygon's edges).
inline std::vector<std::pair<Vector2d, Vector2d>> FootprintAtHeight(
    const TexturedPlane& p, double z) {
  std::vector<double> s_cross;  // positions along the line, in metres
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d along = up.cross(p.plane.normal).normalized();
  const size_t n = p.polygon.size();
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d a = p.frame.ToWorld(p.polygon[i]);
    const Eigen::Vector3d b = p.frame.ToWorld(p.polygon[(i + 1) % n]);
    if ((a.z() - z) * (b.z() - z) > 0 || a.z() == b.z()) continue;
    // Half-open in z ([low, high)), so a vertex on the line counts once.
    if (z == std::max(a.z(), b.z())) continue;
    const double t = (z - a.z()) / (b.z() - a.z());
    s_cross.push_back(along.dot(a + t * (b - a)));
  }
  std::sort(s_cross.begin(), s_cross.end());
  std::vector<std::pair<Vector2d, Vector2d>> segments;
  const Eigen::Vector3d origin = p.plane.Project(Eigen::Vector3d(0, 0, z));
  for (size_t i = 0; i + 1 < s_cross.size(); i += 2) {
    segments.push_back({(origin + s_cross[i] * along).head<2>(),
                        (origin + s_cross[i + 1] * along).head<2>()});
  }
  return segments;
}

inline NavGridTruthGeometry NavGridTruth(
    const std::vector<TexturedPlane>& planes, const NavGridOptions& o) {
  NavGridTruthGeometry truth;
  for (const TexturedPlane& p : planes) {
    std::vector<Eigen::Vector3d> corners;
    double z_lo = INFINITY, z_hi = -INFINITY;
    for (const Vector2d& st : p.polygon) {
      corners.push_back(p.frame.ToWorld(st));
      z_lo = std::min(z_lo, corners.back().z());
      z_hi = std::max(z_hi, corners.back().z());
    }
    Polygon2d xy;
    for (const auto& c : corners) xy.push_back(c.head<2>());
    const bool horizontal = std::abs(p.plane.normal.z()) > 0.99;
    if (horizontal && z_hi < o.min_z_m) {
      truth.floors.push_back(xy);
    } else if (z_hi < o.min_z_m || z_lo > o.max_z_m) {
      continue;
    } else if (std::abs(p.plane.normal.z()) < 0.1) {
      // A vertical plane: its xy footprint within the band, cut at the
      // band's bottom, middle and top (a wall's door opening, cut out of
      // its polygon, is no wall there).
      for (const double z : {o.min_z_m, 0.5 * (o.min_z_m + o.max_z_m),
                             o.max_z_m}) {
        for (const auto& seg : FootprintAtHeight(p, z)) {
          truth.segments.push_back(seg);
        }
      }
    } else {
      truth.areas.push_back(xy);
    }
  }
  return truth;
}

struct NavGridFigures {
  double max_wall_cell_distance_cells = 0;  // occupied cell centre to truth
  double occupied_within_one_cell = 0;      // fraction of occupied cells
  double wall_length_covered = 0;           // fraction of true wall length
  double free_outside_floor = 0;            // free cells off the floor
  double interior_floor_free = 0;           // floor cells away from walls
};

inline NavGridFigures MeasureNavGrid(const NavGrid& grid,
                                     const NavGridTruthGeometry& truth) {
  NavGridFigures f;
  const double res = grid.resolution_m;
  int free = 0, free_outside = 0, interior = 0, interior_free = 0;
  int occupied = 0, occupied_near = 0;
  for (int row = 0; row < grid.cells.rows; ++row) {
    for (int c = 0; c < grid.cells.cols; ++c) {
      const Vector2d x = grid.CellCenter(c, row);
      const NavCell v = grid.At(c, row);
      if (v == NavCell::kOccupied) {
        const double d = truth.Distance(x) / res;
        f.max_wall_cell_distance_cells =
            std::max(f.max_wall_cell_distance_cells, d);
        ++occupied;
        if (d <= 1.0) ++occupied_near;
      }
      if (v == NavCell::kFree) {
        ++free;
        if (truth.FloorDistance(x) > 0.5 * res) ++free_outside;
      }
      if (truth.FloorDistance(x) == 0 && truth.Distance(x) > res) {
        ++interior;
        if (v == NavCell::kFree) ++interior_free;
      }
    }
  }
  f.occupied_within_one_cell =
      occupied > 0 ? double(occupied_near) / occupied : 0.0;
  f.free_outside_floor = free > 0 ? double(free_outside) / free : 1.0;
  f.interior_floor_free = interior > 0 ? double(interior_free) / interior : 0.0;
  // True wall length with an occupied cell within one cell.
  int samples = 0, covered = 0;
  for (const auto& [a, b] : truth.segments) {
    const int n = static_cast<int>(std::ceil((b - a).norm() / (0.25 * res)));
    for (int k = 0; k <= n; ++k) {
      const Vector2d p = a + (b - a) * (double(k) / n);
      const int c =
          static_cast<int>(std::floor((p.x() - grid.origin.x()) / res));
      const int row =
          static_cast<int>(std::floor((p.y() - grid.origin.y()) / res));
      bool hit = false;
      for (int dr = -1; dr <= 1; ++dr) {
        for (int dc = -1; dc <= 1; ++dc) {
          const int cc = c + dc, rr = row + dr;
          hit |= cc >= 0 && rr >= 0 && cc < grid.cells.cols &&
                 rr < grid.cells.rows && grid.At(cc, rr) == NavCell::kOccupied;
        }
      }
      ++samples;
      covered += hit;
    }
  }
  f.wall_length_covered = samples > 0 ? double(covered) / samples : 0.0;
  return f;
}

}  // namespace monomap
