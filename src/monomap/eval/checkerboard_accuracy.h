// Texture accuracy on a known checkerboard: find its inner corners in a
// plane texture with OpenCV, map them to 3D through the texture mapping of
// the map format, and compare with their true positions.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "monomap/eval/point_accuracy.h"
#include "monomap/eval/trajectory_metrics.h"
#include "monomap/map/map.h"

namespace monomap {

struct CheckerboardSpec {
  int inner_corners_x = 9;  // corners along the board's x axis
  int inner_corners_y = 6;  // corners along the board's y axis
  double square_m = 0.04;
  // World position of corner (0, 0) and the board axes.
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d x_axis = Eigen::Vector3d::UnitX();
  Eigen::Vector3d y_axis = Eigen::Vector3d::UnitY();

  Eigen::Vector3d Corner(int i, int j) const {
    return origin + square_m * (i * x_axis + j * y_axis);
  }
  // Whether x lies over the printed board: its inner corners' rectangle
  // grown by the one square of the outer row on every side (in the board's
  // plane, any height above or below it).
  bool Over(const Eigen::Vector3d& x) const;
};

struct CheckerboardAccuracy {
  bool found = false;
  int plane_id = -1;
  int corners_found = 0;
  // The OpenCV detector that found them: "findChessboardCorners" or, where
  // that one fails, "findChessboardCornersSB".
  std::string detector;
  // Distances between the mapped texture corners and the true corners (m).
  ErrorStats error_m;
  // ... after the one rigid motion that best fits the mapped corners to
  // the true ones: the board's shape in the map, without where the map's
  // frame (its odometry's) puts it.
  ErrorStats shape_error_m;
  // Mapped corner positions in world coordinates, in the spec's order.
  std::vector<Eigen::Vector3d> corners_in_world;
};

// Searches every plane texture for the board (cv::findChessboardCorners,
// else the sector-based cv::findChessboardCornersSB, then cornerSubPix) and
// returns the first plane where all inner corners are found. The classic
// detector needs a quiet zone around the board and loses it where the
// plane's extent runs close to the outer squares; the sector-based one
// does not (on the desk texture either one was the sole finder in some
// builds). The detection's ordering ambiguity (start corner, mirroring) is
// resolved by taking the ordering with the smallest error. The corners
// are compared in the truth's frame: truth_from_map (scale, then rigid)
// moves them there, the identity by default (a monocular map's frame is
// its odometry's: see the trajectory alignment, AlignTrajectories).
CheckerboardAccuracy EvaluateCheckerboard(const Map& map,
                                          const CheckerboardSpec& spec,
                                          const Sim3d& truth_from_map = {});

// Reads the `chessboard:` entry of a ground-truth structure YAML
// ({inner_corners_x, inner_corners_y, square_m, origin, x_axis, y_axis}).
CheckerboardSpec ReadCheckerboardYaml(const std::filesystem::path& path);

}  // namespace monomap
