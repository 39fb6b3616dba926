// The navigation grid of a simulated world's true planes, read back from
// the written map.yaml + map.pgm, against the world's true walls.
#include <gtest/gtest.h>

#include <filesystem>

#include "monomap/geometry/polygon.h"
#include "monomap/io/nav_grid_export.h"
#include "monomap/sim/world.h"
#include "monomap/util/error.h"

namespace monomap {
namespace {

namespace fs = std::filesystem;
using Eigen::Vector2d;

// The obstacles a grid should show, straight from the world's planes:
// vertical rectangles reaching into the band as xy segments, horizontal
// planes inside the band as xy polygons.
struct Truth {
  std::vector<std::pair<Vector2d, Vector2d>> segments;
  std::vector<Polygon2d> areas;
  Polygon2d floor;

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

Truth TruthOf(const World& world, const NavGridOptions& o) {
  Truth truth;
  for (const TexturedPlane& p : world.planes) {
    std::vector<Eigen::Vector3d> corners;
    double z_lo = INFINITY, z_hi = -INFINITY;
    for (const Vector2d& st : p.polygon) {
      corners.push_back(p.frame.ToWorld(st));
      z_lo = std::min(z_lo, corners.back().z());
      z_hi = std::max(z_hi, corners.back().z());
    }
    Polygon2d xy;
    for (const auto& c : corners) xy.push_back(c.head<2>());
    if (&p == &world.planes[world.floor_plane]) {
      truth.floor = xy;
    } else if (z_hi < o.min_z_m || z_lo > o.max_z_m) {
      continue;
    } else if (std::abs(p.plane.normal.z()) < 0.1) {
      // A vertical rectangle: its xy footprint is the segment between the
      // two farthest corners.
      std::pair<Vector2d, Vector2d> seg{xy[0], xy[0]};
      for (const Vector2d& a : xy) {
        for (const Vector2d& b : xy) {
          if ((a - b).norm() > (seg.first - seg.second).norm()) seg = {a, b};
        }
      }
      truth.segments.push_back(seg);
    } else {
      truth.areas.push_back(xy);
    }
  }
  return truth;
}

struct Figures {
  double max_wall_cell_distance_cells = 0;  // occupied cell centre to truth
  double wall_length_covered = 0;           // fraction of true wall length
  double free_outside_floor = 0;            // free cells off the floor
  double interior_floor_free = 0;           // floor cells away from walls
};

Figures Measure(const NavGrid& grid, const Truth& truth) {
  Figures f;
  const double res = grid.resolution_m;
  int free = 0, free_outside = 0, interior = 0, interior_free = 0;
  for (int row = 0; row < grid.cells.rows; ++row) {
    for (int c = 0; c < grid.cells.cols; ++c) {
      const Vector2d x = grid.CellCenter(c, row);
      const NavCell v = grid.At(c, row);
      if (v == NavCell::kOccupied) {
        f.max_wall_cell_distance_cells =
            std::max(f.max_wall_cell_distance_cells, truth.Distance(x) / res);
      }
      if (v == NavCell::kFree) {
        ++free;
        if (DistanceToPolygon(truth.floor, x) > 0.5 * res) ++free_outside;
      }
      if (PointInPolygon(truth.floor, x) &&
          DistanceToPolygon(truth.floor, x) == 0 && truth.Distance(x) > res) {
        ++interior;
        if (v == NavCell::kFree) ++interior_free;
      }
    }
  }
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

TEST(NavGridTest, TrueWallsOfEveryWorldWithinOneCell) {
  for (const std::string& name : WorldNames()) {
    for (double resolution : {0.05, 0.1}) {
      SCOPED_TRACE(name + " at " + std::to_string(resolution) + " m");
      const World world = MakeWorld(name, 1, 20.0);
      Map map;
      map.planes = world.planes;
      NavGridOptions options;
      options.resolution_m = resolution;
      NavGridReport report;
      const NavGrid made = MakeNavGrid(map, options, &report);
      const fs::path dir = fs::temp_directory_path() / "monomap_nav_grid_test";
      fs::remove_all(dir);
      WriteNavGrid(dir, made, options);
      // Measure what a map_server user gets: the files.
      const NavGrid grid = ReadNavGrid(dir / "map.yaml");
      ASSERT_EQ(grid.cells.size(), made.cells.size());
      EXPECT_EQ(cv::norm(grid.cells, made.cells, cv::NORM_INF), 0.0);
      EXPECT_EQ(report.num_floor_planes, 1);
      EXPECT_GT(report.num_occupied, 0);

      const Figures f = Measure(grid, TruthOf(world, options));
      std::printf(
          "%-10s %.2f m: wall cells <= %.2f cells from truth, %.1f%% "
          "of wall length covered, %.1f%% of interior floor free, "
          "%.2f%% free cells off the floor\n",
          name.c_str(), resolution, f.max_wall_cell_distance_cells,
          100 * f.wall_length_covered, 100 * f.interior_floor_free,
          100 * f.free_outside_floor);
      EXPECT_LE(f.max_wall_cell_distance_cells, 1.0);
      EXPECT_GE(f.wall_length_covered, 0.99);
      EXPECT_GE(f.interior_floor_free, 0.99);
      EXPECT_EQ(f.free_outside_floor, 0.0);
    }
  }
}

TEST(NavGridTest, BandSelectsObstacles) {
  // The room's metal cabinet is 1.8 m tall, the other boxes 0.6 and 0.75 m:
  // a band above 0.8 m keeps walls and the cabinet only.
  const World world = MakeWorld("room", 1, 20.0);
  Map map;
  map.planes = world.planes;
  NavGridOptions low, high;
  high.min_z_m = 0.8;
  NavGridReport r_low, r_high;
  MakeNavGrid(map, low, &r_low);
  MakeNavGrid(map, high, &r_high);
  // 4 walls, 5 faces of each low box and the cabinet's 4 sides (its top is
  // above the band) in the default band; 4 walls + 4 cabinet sides above
  // 0.8 m.
  EXPECT_EQ(r_low.num_obstacle_planes, 18);
  EXPECT_EQ(r_high.num_obstacle_planes, 8);
  EXPECT_GT(r_high.num_free, r_low.num_free);
}

TEST(NavGridTest, BadOptionsAndEmptyMapsAreRejected) {
  NavGridOptions o;
  o.min_z_m = 2.0;
  EXPECT_THROW(o.Check(), OptionsError);
  o = NavGridOptions();
  o.resolution_m = 0;
  EXPECT_THROW(o.Check(), OptionsError);
  o = NavGridOptions();
  o.free_thresh = 0.3;  // unknown pixels would read as free
  EXPECT_THROW(o.Check(), OptionsError);
  EXPECT_THROW(MakeNavGrid(Map(), NavGridOptions()), StageError);
  const fs::path dir = fs::temp_directory_path() / "monomap_nav_grid_bad";
  fs::create_directories(dir);
  std::FILE* f = std::fopen((dir / "map.yaml").c_str(), "w");
  std::fputs("image: map.pgm\nresolution: 0.05\n", f);
  std::fclose(f);
  try {
    ReadNavGrid(dir / "map.yaml");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("origin"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace monomap
