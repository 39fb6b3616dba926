// A laser-free navigation map from the map's planes: a ROS map_server
// occupancy grid (map.pgm + map.yaml) that nav2 and move_base load as is.
// Occupied: the parts of non-floor planes inside a height band (walls,
// obstacle sides and tops at robot height). Free: the floor planes' area
// not occupied. Unknown: everything else. The grid lies in the map's world
// xy plane (world z up, as the odometry frame of a ground robot); see
// docs/map-format.md, "Navigation grid".
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <opencv2/core.hpp>
#include <string>

#include "monomap/map/map.h"

namespace monomap {

struct NavGridOptions {
  // Cell size (m).
  double resolution_m = 0.05;
  // Height band (world z, m) in which a plane is an obstacle: above the
  // floor and below the robot's top.
  double min_z_m = 0.1;
  double max_z_m = 1.5;
  // A plane whose normal is within this angle of world z is horizontal;
  // horizontal planes entirely below min_z_m are floor.
  double horizontal_max_tilt_deg = 10.0;
  // Unknown border kept around the planes (m).
  double margin_m = 0.25;
  // map.yaml thresholds on occupancy probability (map_server's trinary
  // mode reads a pixel value v as probability (255 - v) / 255).
  double occupied_thresh = 0.65;
  double free_thresh = 0.196;
  // Largest grid side in cells: guards against a stray far plane making a
  // huge image.
  int max_cells_per_side = 20000;

  // Throws OptionsError naming the field.
  void Check() const;
};

enum class NavCell : uint8_t { kUnknown = 0, kFree = 1, kOccupied = 2 };

// An occupancy grid in the world xy plane. Cell (column c, row r) covers
// x in origin.x + [c, c+1) * resolution, y in origin.y + [r, r+1) *
// resolution: row 0 is the lowest y (as ROS OccupancyGrid; the PGM image
// is written flipped, its top row is the highest y).
struct NavGrid {
  double resolution_m = 0.05;
  Eigen::Vector2d origin = Eigen::Vector2d::Zero();  // lower-left corner
  cv::Mat1b cells;  // NavCell values, rows x cols

  NavCell At(int col, int row) const {
    return static_cast<NavCell>(cells(row, col));
  }
  // Centre of a cell in world x, y.
  Eigen::Vector2d CellCenter(int col, int row) const {
    return origin + resolution_m * Eigen::Vector2d(col + 0.5, row + 0.5);
  }
};

struct NavGridReport {
  int width = 0;
  int height = 0;
  int num_floor_planes = 0;
  int num_obstacle_planes = 0;  // planes with a part inside the band
  int num_free = 0;
  int num_occupied = 0;
  int num_unknown = 0;
};

// Rasterizes the planes of `map`. Throws OptionsError on bad options and
// StageError if the map has no floor plane and no obstacle in the band, or
// the grid would exceed max_cells_per_side.
NavGrid MakeNavGrid(const Map& map, const NavGridOptions& options,
                    NavGridReport* report = nullptr);

// Writes <dir>/map.pgm (P5: occupied 0, free 254, unknown 205) and
// <dir>/map.yaml (image, mode trinary, resolution, origin [x, y, 0],
// negate 0, occupied_thresh, free_thresh); `dir` is created if missing,
// each file written atomically. Throws OutputError on failure.
void WriteNavGrid(const std::filesystem::path& dir, const NavGrid& grid,
                  const NavGridOptions& options);

// Reads a map_server map.yaml and its image back (trinary interpretation
// with the file's thresholds and negate flag). Throws InputError naming
// the file and field.
NavGrid ReadNavGrid(const std::filesystem::path& yaml_path);

}  // namespace monomap
