// Data types shared by the stages. No algorithms here: stages in
// tracking/, triangulation/, planes/, texture/, rendering/ read and write
// these types and talk to each other only through them.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "monomap/camera/camera.h"
#include "monomap/geometry/plane.h"
#include "monomap/geometry/polygon.h"
#include "monomap/geometry/rigid3.h"

namespace monomap {

using FeatureId = int64_t;

// One sighting of a tracked feature: frame index into the dataset and the
// raw (distorted) pixel position, pixel centres at integer coordinates.
struct Observation {
  int frame = 0;
  Eigen::Vector2d px = Eigen::Vector2d::Zero();
};

// A feature tracked by KLT over consecutive frames. The id is unique over
// the whole sequence and never reused.
struct Track {
  FeatureId id = 0;
  std::vector<Observation> observations;  // sorted by frame
};

// A triangulated 3D point, carrying the id of its track.
struct Landmark {
  FeatureId id = 0;
  Eigen::Vector3d x_in_world = Eigen::Vector3d::Zero();
  Eigen::Vector3f color = Eigen::Vector3f::Zero();  // RGB in [0, 255]
  int num_observations = 0;
  double mean_reprojection_error_px = 0.0;
  double triangulation_angle_deg = 0.0;
  // Mean distance (m) from the observing camera centres: depth uncertainty
  // grows with it, so plane fitting scales its inlier threshold by it.
  double mean_depth_m = 0.0;
  // Covariance of x_in_world (m^2) for observations with 1 px isotropic
  // noise, (J^T J)^-1 of the reprojection error at the solution: how well
  // the viewing geometry fixes the point in each direction (a far point
  // seen along a short baseline is loose along its rays). Scale by the
  // tracker's noise squared. Zero when unknown.
  Eigen::Matrix3d covariance_m2_per_px2 = Eigen::Matrix3d::Zero();
  int plane_id = -1;  // index of the plane it lies on, -1 if none
};

// A plane found among the landmarks (stage 3), before it has a texture.
struct PlaneSegment {
  int id = 0;
  Plane plane;
  // In-plane frame; inlier_st are the inliers' coordinates in it.
  PlaneFrame frame;
  std::vector<FeatureId> inlier_ids;
  std::vector<Eigen::Vector2d> inlier_st;
  // Bounded extent in (s, t) plane coordinates (metres).
  Polygon2d polygon;
  // The extent its inliers support (their outline), when `polygon` reaches
  // further: over the points plane fitting absorbed
  // (PlaneFittingOptions::extend_to_absorbed) or over what plane growth
  // added; empty otherwise (then it is `polygon`).
  Polygon2d landmark_polygon;
  // RMS point-to-plane distance of the inliers (m).
  double rms_distance_m = 0.0;
};

// A timestamped camera pose.
struct TimedPose {
  double timestamp = 0.0;
  Rigid3d world_from_cam;
};

// A feature on a plane: 3D point and where it lies in the plane texture.
struct PlaneFeature {
  FeatureId id = 0;
  Eigen::Vector3d x_in_world = Eigen::Vector3d::Zero();
  Eigen::Vector2d texture_px = Eigen::Vector2d::Zero();  // (column, row)
};

// A bounded plane with its texture. The centre of texture pixel (c, r)
// shows frame.ToWorld(((c + 0.5) / pixels_per_meter,
// (r + 0.5) / pixels_per_meter)).
struct TexturedPlane {
  int id = 0;
  Plane plane;
  PlaneFrame frame;
  double pixels_per_meter = 0.0;
  // BGRA, 8 bit; alpha 0 where no image saw the plane.
  cv::Mat texture;
  // Extent as a polygon of (s, t) plane coordinates in metres.
  Polygon2d polygon;
  // The polygon its inliers support, when `polygon` reaches further (over
  // absorbed points or grown cells: PlaneSegment::landmark_polygon); empty
  // otherwise. Localization renders only this
  // (RendererOptions::clip_to_landmark_polygon).
  Polygon2d landmark_polygon;
  std::vector<PlaneFeature> features;

  // World point -> texture pixel coordinates (column, row) and back.
  Eigen::Vector2d TextureFromWorld(const Eigen::Vector3d& x) const {
    return frame.ToPlane(x) * pixels_per_meter - Eigen::Vector2d(0.5, 0.5);
  }
  Eigen::Vector3d WorldFromTexture(const Eigen::Vector2d& px) const {
    return frame.ToWorld((px + Eigen::Vector2d(0.5, 0.5)) / pixels_per_meter);
  }
};

// The whole map: what `monomap build` writes and `render`/`localize` read.
struct Map {
  // The lens the map's geometry goes with (refined by bundle adjustment's
  // self-calibration, if it was on and the data constrained the lens).
  Camera camera;
  // The calibration the map was built from, when `camera` differs from it.
  std::optional<Camera> given_camera;
  std::vector<TexturedPlane> planes;
  std::vector<Landmark> landmarks;
  std::vector<TimedPose> trajectory;  // refined world_from_cam per frame
};

}  // namespace monomap
