// COLMAP sparse model in COLMAP's text format (cameras.txt, images.txt,
// points3D.txt), so COLMAP and OpenMVS can continue from a monomap map, and
// a reader for the same files. See docs/map-format.md, "COLMAP export".
//
// COLMAP puts the image origin at the top-left corner of the top-left
// pixel (its centre is (0.5, 0.5)); monomap puts pixel centres at integers,
// so principal points and 2D points are shifted by +0.5 on export.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "monomap/map/map.h"

namespace monomap {

// The model as the three text files hold it.
struct ColmapModel {
  struct Camera {
    int id = 1;
    std::string model;  // "PINHOLE", "OPENCV", "FULL_OPENCV", ...
    int width = 0;
    int height = 0;
    std::vector<double> params;  // in COLMAP's order for `model`
  };
  struct Point2D {
    Eigen::Vector2d xy = Eigen::Vector2d::Zero();  // COLMAP pixel convention
    int64_t point3d_id = -1;                       // -1: no 3D point
  };
  struct Image {
    int id = 0;
    Eigen::Quaterniond cam_from_world_rotation = Eigen::Quaterniond::Identity();
    Eigen::Vector3d cam_from_world_translation = Eigen::Vector3d::Zero();
    int camera_id = 1;
    std::string name;
    std::vector<Point2D> points2d;
  };
  struct TrackElement {
    int image_id = 0;
    int point2d_idx = 0;
  };
  struct Point3D {
    int64_t id = 0;
    Eigen::Vector3d xyz = Eigen::Vector3d::Zero();
    Eigen::Vector3i rgb = Eigen::Vector3i::Zero();
    double error = 0.0;  // mean reprojection error (px), 0 without a track
    std::vector<TrackElement> track;
  };
  std::vector<Camera> cameras;
  std::vector<Image> images;
  std::vector<Point3D> points;
};

// What an export produced.
struct ColmapExportReport {
  std::string camera_model;
  int num_images = 0;
  int num_points = 0;
  // Landmarks with at least one observation in the feature table.
  int num_points_with_track = 0;
  int num_observations = 0;
  // Observations dropped: frame outside the trajectory or point behind the
  // camera.
  int num_dropped_observations = 0;
  // Mean over observations of the reprojection error (px) with the map's
  // camera and refined poses.
  double mean_reprojection_error_px = 0.0;
};

// The COLMAP camera for monomap's camera: PINHOLE without distortion,
// OPENCV (fx fy cx cy k1 k2 p1 p2) when k3 = 0, else FULL_OPENCV with
// k4 = k5 = k6 = 0 (the same polynomial); OPENCV_FISHEYE (fx fy cx cy k1 k2
// k3 k4) for an equidistant lens.
ColmapModel::Camera ColmapCameraFromCamera(const Camera& camera, int id = 1);
// Back from SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV,
// OPENCV_FISHEYE and FULL_OPENCV with k4 = k5 = k6 = 0. Throws InputError
// naming the model for any other camera.
Camera CameraFromColmapCamera(const ColmapModel::Camera& camera);

// Builds the model: the map's camera; one image per trajectory pose (id =
// frame index + 1, named image_names[frame], or "frame_NNNNNN.png" when
// image_names is empty) with cam_from_world = the refined pose inverted;
// one 3D point per landmark (id = its feature id) whose track holds the
// observations of the feature table's track with the same id. Without
// tracks (empty `tracks`) images have no 2D points and tracks are empty.
// Throws OutputError if image_names has the wrong size or landmark ids
// repeat.
ColmapModel MakeColmapModel(const Map& map, const std::vector<Track>& tracks,
                            const std::vector<std::string>& image_names,
                            ColmapExportReport* report = nullptr);

// Writes cameras.txt, images.txt and points3D.txt into `dir` (created if
// missing; each file atomically). Throws OutputError on failure.
void WriteColmapText(const std::filesystem::path& dir,
                     const ColmapModel& model);

// Reads the three text files. Throws InputError naming file and line on a
// malformed line, an unknown camera or image id, or a track element that
// does not point back at its point.
ColmapModel ReadColmapText(const std::filesystem::path& dir);

}  // namespace monomap
