// Exact rendering of textured planes into a distorted camera image, and
// the camera effects (exposure changes, blur, sensor noise) of a real one.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "monomap/camera/camera.h"
#include "monomap/geometry/rigid3.h"
#include "monomap/map/map.h"

namespace monomap {

struct RenderOptions {
  // Samples per pixel along each axis (1 = one ray per pixel centre). Mip
  // mapping already limits aliasing; 2 also smooths polygon edges.
  int supersampling = 1;
  // Radiance (grey level) of rays that hit no plane.
  double background = 40.0;

  void Check() const;
};

// Renders a set of planes seen by a (distorted) camera: for every pixel the
// ray through it (precomputed once) hits the nearest plane inside its
// polygon, whose texture is sampled trilinearly from a mip pyramid with the
// level chosen from the pixel's footprint on the plane.
class SceneRenderer {
 public:
  SceneRenderer(const Camera& camera, const RenderOptions& options = {});

  // Adds a plane (its geometry and a mip pyramid of its texture's BGR
  // channels) and returns its index. Throws OptionsError for an empty
  // texture, a non-positive pixels_per_meter or fewer than 3 vertices.
  int AddPlane(const TexturedPlane& plane);
  // Moves plane i (for moving objects): new plane and frame, same texture.
  void SetPlanePose(int i, const Plane& plane, const PlaneFrame& frame);
  // Hidden planes are skipped.
  void SetPlaneVisible(int i, bool visible);
  int num_planes() const { return static_cast<int>(planes_.size()); }
  const Camera& camera() const { return camera_; }

  // A view-dependent bright blob on plane `plane_index` (a specular
  // reflection): adds strength * exp(-d^2 / (2 radius^2)) grey levels at
  // distance d from `centre`.
  struct Highlight {
    int plane_index = -1;
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    double radius_m = 0.15;
    double strength = 100.0;
  };

  // Radiance image (CV_32FC3, BGR, grey levels 0..255 before effects).
  // Parallel over rows (TBB); the result does not depend on the threads.
  cv::Mat Render(const Rigid3d& world_from_cam,
                 const std::vector<Highlight>& highlights = {}) const;
  // Index of the plane seen at the centre of each pixel (CV_32S, -1 for
  // none), for tests and masks.
  cv::Mat RenderPlaneIndex(const Rigid3d& world_from_cam) const;

 private:
  struct Entry {
    Plane plane;
    PlaneFrame frame;
    Polygon2d polygon;
    Eigen::Vector2d lo, hi;  // polygon bounds
    double ppm = 0.0;
    std::vector<cv::Mat> levels;  // CV_8UC3 mip pyramid
    bool visible = true;
  };
  // Nearest visible plane hit by the ray (c + t d); returns its index or -1.
  int Intersect(const Eigen::Vector3d& c, const Eigen::Vector3d& d,
                const std::vector<double>& c_dist, double* t_hit,
                Eigen::Vector2d* st_hit) const;

  Camera camera_;
  RenderOptions options_;
  int grid_w_ = 0, grid_h_ = 0;
  std::vector<Eigen::Vector3d> rays_;  // (x, y, 1) per sample
  std::vector<float> ray_angle_;       // angular size of a sample (rad)
  std::vector<Entry> planes_;
};

// Real-camera effects on top of the exact radiance.
struct CameraEffectsOptions {
  // Relative amplitude of the smooth auto-exposure/gain variation over
  // time (0 = constant exposure).
  double exposure_variation = 0.12;
  // Main period of the exposure variation (s).
  double exposure_period_s = 9.0;
  // Gaussian optical blur (pixels, 0 = none).
  double blur_sigma_px = 0.6;
  // Gaussian sensor noise (grey levels, 0 = none).
  double noise_sigma = 2.0;
  // Write BGR images instead of 8-bit grey.
  bool color = false;

  // Everything off: images are the quantised radiance.
  static CameraEffectsOptions None();
  void Check() const;
};

// Exposure gain at time t (s since the first frame): smooth, near 1.
double ExposureGain(double t, const CameraEffectsOptions& options,
                    uint64_t seed);

// Blur, gain, noise (seeded by `noise_seed`) and quantisation of a radiance
// image to CV_8UC1 (or CV_8UC3 if options.color).
cv::Mat ApplyCameraEffects(const cv::Mat& radiance, double t,
                           const CameraEffectsOptions& options,
                           uint64_t seed, uint64_t noise_seed);

// A textured disc of radius `radius_m` (polygon of 32 vertices) used as a
// moving object: a high-contrast target not part of the structure.
TexturedPlane MakeDiscObject(double radius_m, double pixels_per_meter,
                             uint64_t seed);

// Plane and frame placing a disc object made by MakeDiscObject with its
// centre at `centre` facing direction `towards` (unit), upright (v down).
void PlaceDisc(double radius_m, const Eigen::Vector3d& centre,
               const Eigen::Vector3d& towards, Plane* plane,
               PlaneFrame* frame);

// Mirror point on the horizontal plane z = floor_z where `light` reflects
// into the camera at `camera_centre`; false if the geometry has none.
bool SpecularPoint(const Eigen::Vector3d& light,
                   const Eigen::Vector3d& camera_centre, double floor_z,
                   Eigen::Vector3d* point);

}  // namespace monomap
