#include "monomap/localization/mcc.h"

#include <tbb/parallel_invoke.h>

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "monomap/tracking/pyramidal_lk.h"
#include "monomap/util/angles.h"
#include "monomap/util/error.h"

namespace monomap {

void MccOptions::Check() const {
  CheckOption(width >= 16 && height >= 16, "mcc.width/height", "must be >= 16");
  CheckOption(max_corners >= 4, "mcc.max_corners", "must be >= 4");
  CheckOption(corner_quality > 0 && corner_quality < 1, "mcc.corner_quality",
              "must be in (0, 1)");
  CheckOption(min_corner_distance_px >= 0, "mcc.min_corner_distance_px",
              "must be >= 0");
  CheckOption(border_px >= 0, "mcc.border_px", "must be >= 0");
  CheckOption(klt_window >= 5 && klt_window % 2 == 1, "mcc.klt_window",
              "must be odd and >= 5");
  CheckOption(klt_levels >= 0, "mcc.klt_levels", "must be >= 0");
  CheckOption(max_forward_backward_px > 0, "mcc.max_forward_backward_px",
              "must be > 0");
  CheckOption(ransac_threshold_px > 0, "mcc.ransac_threshold_px",
              "must be > 0");
  CheckOption(ransac_iterations >= 1, "mcc.ransac_iterations", "must be >= 1");
  CheckOption(min_inliers >= 6, "mcc.min_inliers", "must be >= 6");
  CheckOption(max_translation_m > 0, "mcc.max_translation_m", "must be > 0");
  CheckOption(max_rotation_deg > 0, "mcc.max_rotation_deg", "must be > 0");
  CheckOption(iterations >= 1, "mcc.iterations", "must be >= 1");
  CheckOption(converged_px >= 0, "mcc.converged_px", "must be >= 0");
  CheckOption(std::isfinite(extra_mip_bias) && std::abs(extra_mip_bias) <= 4,
              "mcc.extra_mip_bias", "must be finite, within [-4, 4]");
}

namespace {

// The caller's renderer with the extra mip bias (options checked first).
Renderer MccRenderer(const Renderer* renderer, const MccOptions& options) {
  options.Check();
  if (renderer == nullptr) throw OptionsError("mcc: null renderer");
  return renderer->WithMipBias(renderer->options().mip_bias +
                               options.extra_mip_bias);
}

}  // namespace

MonteCarloCorrector::MonteCarloCorrector(const Renderer* renderer,
                                         const Camera& camera,
                                         const MccOptions& options)
    : renderer_(MccRenderer(renderer, options)), options_(options) {
  camera.Check();
  render_camera_ = camera.Pinhole().Scaled(options_.width, options_.height);
}

namespace {

cv::Mat CvFromRigid(const Rigid3d& cam_from_world, cv::Mat* tvec) {
  const Eigen::Vector3d w =
      RotationVectorFromQuaternion(cam_from_world.rotation);
  cv::Mat rvec = (cv::Mat_<double>(3, 1) << w.x(), w.y(), w.z());
  *tvec = (cv::Mat_<double>(3, 1) << cam_from_world.translation.x(),
           cam_from_world.translation.y(), cam_from_world.translation.z());
  return rvec;
}

Rigid3d RigidFromCv(const cv::Mat& rvec, const cv::Mat& tvec) {
  const Eigen::Vector3d w(rvec.at<double>(0), rvec.at<double>(1),
                          rvec.at<double>(2));
  const Eigen::Vector3d t(tvec.at<double>(0), tvec.at<double>(1),
                          tvec.at<double>(2));
  return Rigid3d(QuaternionFromRotationVector(w), t);
}

}  // namespace

namespace {

// A render of the map from the start pose, the corners to track in it and
// the KLT pyramids of the render and of the live image.
struct RenderedView {
  cv::Mat render, depth;
  std::vector<cv::Point2f> corners;
  std::vector<cv::Mat> render_pyramid, live_pyramid;
};

// 3D-2D matches: render corners back-projected with the render's depth,
// and where KLT found them in the live image.
struct Matches {
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image;
};

// The bounding box of the mask grown by 3 px (within the image); empty
// without any masked pixel. The map often covers half of the view, and
// the work on masked pixels is done in this box only, with the same
// result as over the whole image: see DetectCorners.
cv::Rect MaskBox(const cv::Mat& mask) {
  constexpr int kMargin = 3;
  const cv::Rect box = cv::boundingRect(mask);
  if (box.empty()) return box;
  return (box + cv::Size(2 * kMargin, 2 * kMargin) -
          cv::Point(kMargin, kMargin)) &
         cv::Rect(0, 0, mask.cols, mask.rows);
}

// Shi-Tomasi corners of `render` where `mask` is set, searched in `box`
// (MaskBox). Equal to a search of the whole image: the corner response
// reads the pixels around the box, its 3x3 sums and the local-maximum
// test reach 2 px from a masked pixel, and goodFeaturesToTrack orders
// equal responses row-major in either image.
void DetectCorners(const cv::Mat& render, const cv::Mat& mask,
                   const cv::Rect& box, const MccOptions& o,
                   std::vector<cv::Point2f>* corners) {
  corners->clear();
  if (box.empty()) return;
  cv::goodFeaturesToTrack(render(box), *corners, o.max_corners,
                          o.corner_quality, o.min_corner_distance_px,
                          mask(box));
  const cv::Point2f offset(static_cast<float>(box.x),
                           static_cast<float>(box.y));
  for (cv::Point2f& c : *corners) c += offset;
}

// KLT assumes brightness constancy: the live image brought to the
// render's gain and offset (mean and spread over the map pixels, all in
// `box`), else exposure changes bias the tracks by tenths of a pixel.
cv::Mat MatchGain(const cv::Mat& render, const cv::Mat& live_raw,
                  const cv::Mat& mask, const cv::Rect& box) {
  if (box.empty()) return live_raw;
  cv::Scalar mr, sr, ml, sl;
  cv::meanStdDev(render(box), mr, sr, mask(box));
  cv::meanStdDev(live_raw(box), ml, sl, mask(box));
  if (!(sl[0] > 1.0 && sr[0] > 1.0)) return live_raw;
  const double gain = sr[0] / sl[0];
  cv::Mat live;
  live_raw.convertTo(live, CV_8U, gain, mr[0] - gain * ml[0]);
  return live;
}

RenderedView RenderView(const Renderer& renderer, const Camera& camera,
                        const MccOptions& o, const PyrLkOptions& lk,
                        const cv::Mat& live_raw, const Rigid3d& start) {
  RenderedView v;
  renderer.Render(camera, start, &v.render, &v.depth);
  // Corners only well inside the map's silhouette.
  cv::Mat mask = v.depth > 0.0f;
  if (o.border_px > 0) {
    cv::erode(mask, mask,
              cv::getStructuringElement(
                  cv::MORPH_RECT,
                  cv::Size(2 * o.border_px + 1, 2 * o.border_px + 1)));
  }
  const cv::Rect box = MaskBox(mask);
  // Corner detection on the render runs beside the preparation of the two
  // images for KLT (the full-size refinement is one correction at a time,
  // and these steps are most of its time).
  tbb::parallel_invoke(
      [&] { DetectCorners(v.render, mask, box, o, &v.corners); },
      [&] {
        BuildLkPyramid(v.render, lk, &v.render_pyramid);
        BuildLkPyramid(MatchGain(v.render, live_raw, mask, box), lk,
                       &v.live_pyramid);
      });
  return v;
}

// Depth of the render at a corner (0: none or outside).
float DepthAt(const cv::Mat& depth, const cv::Point2f& corner) {
  const int u = cvRound(corner.x), w = cvRound(corner.y);
  if (u < 0 || w < 0 || u >= depth.cols || w >= depth.rows) return 0.0f;
  return depth.at<float>(w, u);
}

// Tracks the corners into the live image and back; those that return
// within max_forward_backward_px and have depth become matches. Only the
// corners tracked forward, with depth, are tracked back (the points are
// tracked independently, so the others would be dropped anyway).
Matches TrackCorners(const RenderedView& v, const Camera& c,
                     const MccOptions& o, PyrLkOptions lk,
                     const Rigid3d& start) {
  const std::vector<cv::Point2f>& corners = v.corners;
  std::vector<cv::Point2f> fwd, fwd_kept, back;
  std::vector<uchar> st_f, st_b;
  std::vector<float> err, depth;
  std::vector<size_t> kept;
  PyramidalLk(v.render_pyramid, v.live_pyramid, corners, &fwd, &st_f, &err, lk);
  for (size_t i = 0; i < corners.size(); ++i) {
    const float z = DepthAt(v.depth, corners[i]);
    if (!st_f[i] || !(z > 0.0f)) continue;
    kept.push_back(i);
    depth.push_back(z);
    fwd_kept.push_back(fwd[i]);
    back.push_back(corners[i]);  // backward starts at the corner
  }
  lk.use_initial_guess = true;
  PyramidalLk(v.live_pyramid, v.render_pyramid, fwd_kept, &back, &st_b, &err,
              lk);
  Matches m;
  for (size_t j = 0; j < kept.size(); ++j) {
    const cv::Point2f& corner = corners[kept[j]];
    const cv::Point2f d = back[j] - corner;
    if (!st_b[j] ||
        d.dot(d) > o.max_forward_backward_px * o.max_forward_backward_px) {
      continue;
    }
    // Back-project the corner (exact at the pixel centre it was found on).
    const float z = depth[j];
    const Eigen::Vector3d x_cam((corner.x - c.cx) / c.fx * z,
                                (corner.y - c.cy) / c.fy * z, z);
    const Eigen::Vector3d x = start * x_cam;
    m.object.emplace_back(x.x(), x.y(), x.z());
    m.image.emplace_back(fwd_kept[j].x, fwd_kept[j].y);
  }
  return m;
}

// RMS reprojection error (px) of the points at pose (r, t).
double RmsReprojection(const std::vector<cv::Point3d>& object,
                       const std::vector<cv::Point2d>& image, const cv::Mat& k,
                       const cv::Mat& r, const cv::Mat& t) {
  std::vector<cv::Point2d> proj;
  cv::projectPoints(object, r, t, k, cv::noArray(), proj);
  double sum_sq = 0.0;
  for (size_t i = 0; i < proj.size(); ++i) {
    const cv::Point2d d = proj[i] - image[i];
    sum_sq += d.dot(d);
  }
  return std::sqrt(sum_sq / proj.size());
}

// The pose of the matches by PnP: RANSAC, then Levenberg-Marquardt on the
// inliers; false if too few inliers or the fit is worse than the RANSAC
// threshold. Sets stats' inliers and rms.
bool SolvePose(const Matches& m, const Camera& c, const MccOptions& o,
               const Rigid3d& start, Rigid3d* out, MccResult* stats) {
  const cv::Mat k =
      (cv::Mat_<double>(3, 3) << c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1);
  cv::Mat tvec;
  cv::Mat rvec = CvFromRigid(start.Inverse(), &tvec);
  // RANSAC overwrites its guess; the start pose is refined again below.
  cv::Mat rvec_start = rvec.clone(), tvec_start = tvec.clone();
  std::vector<int> inliers;
  const bool ok =
      cv::solvePnPRansac(m.object, m.image, k, cv::noArray(), rvec, tvec,
                         /*useExtrinsicGuess=*/true, o.ransac_iterations,
                         static_cast<float>(o.ransac_threshold_px), 0.999,
                         inliers, cv::SOLVEPNP_ITERATIVE);
  stats->inliers = static_cast<int>(inliers.size());
  if (!ok || static_cast<int>(inliers.size()) < o.min_inliers) return false;
  std::vector<cv::Point3d> in_obj;
  std::vector<cv::Point2d> in_img;
  for (int i : inliers) {
    in_obj.push_back(m.object[i]);
    in_img.push_back(m.image[i]);
  }
  // The pose solvePnPRansac returns for its inliers occasionally runs off
  // (tens of px of error, metres away, on simulated hallways), so the
  // inliers are fitted by Levenberg-Marquardt from both that pose and the
  // start pose, and the better fit is kept.
  cv::solvePnPRefineLM(in_obj, in_img, k, cv::noArray(), rvec, tvec);
  cv::solvePnPRefineLM(in_obj, in_img, k, cv::noArray(), rvec_start,
                       tvec_start);
  double best_rms = RmsReprojection(in_obj, in_img, k, rvec, tvec);
  const double start_rms =
      RmsReprojection(in_obj, in_img, k, rvec_start, tvec_start);
  if (start_rms < best_rms) {
    best_rms = start_rms;
    rvec = rvec_start;
    tvec = tvec_start;
  }
  stats->rms_reprojection_px = best_rms;
  if (!(best_rms <= o.ransac_threshold_px)) return false;
  // How far the solved pose moves the inliers' projections from where the
  // start pose put them.
  cv::Mat r0, t0 = cv::Mat();
  r0 = CvFromRigid(start.Inverse(), &t0);
  std::vector<cv::Point2d> before, after;
  cv::projectPoints(in_obj, r0, t0, k, cv::noArray(), before);
  cv::projectPoints(in_obj, rvec, tvec, k, cv::noArray(), after);
  double sum_sq = 0.0;
  for (size_t i = 0; i < before.size(); ++i) {
    const cv::Point2d d = after[i] - before[i];
    sum_sq += d.dot(d);
  }
  stats->shift_px = std::sqrt(sum_sq / before.size());
  *out = RigidFromCv(rvec, tvec).Inverse();
  return true;
}

}  // namespace

bool MonteCarloCorrector::Round(const cv::Mat& live_raw, const Rigid3d& start,
                                Rigid3d* out, MccResult* stats) const {
  PyrLkOptions lk;
  lk.window = options_.klt_window;
  lk.levels = options_.klt_levels;
  const RenderedView view =
      RenderView(renderer_, render_camera_, options_, lk, live_raw, start);
  stats->corners = static_cast<int>(view.corners.size());
  stats->tracked = stats->inliers = 0;
  if (stats->corners < options_.min_inliers) return false;
  const Matches matches =
      TrackCorners(view, render_camera_, options_, lk, start);
  stats->tracked = static_cast<int>(matches.object.size());
  if (stats->tracked < options_.min_inliers) return false;
  return SolvePose(matches, render_camera_, options_, start, out, stats);
}

MccResult MonteCarloCorrector::Correct(const cv::Mat& live,
                                       const Rigid3d& world_from_cam) const {
  if (live.cols != options_.width || live.rows != options_.height ||
      live.type() != CV_8UC1) {
    throw InputError("mcc: live image must be 8-bit grey " +
                     std::to_string(options_.width) + "x" +
                     std::to_string(options_.height));
  }
  MccResult r;
  Rigid3d pose = world_from_cam;
  bool any = false;
  for (int it = 0; it < options_.iterations; ++it) {
    Rigid3d next;
    MccResult round_stats;
    if (!Round(live, pose, &next, &round_stats)) {
      if (!any) r = round_stats;  // report why the first round failed
      break;
    }
    r = round_stats;
    r.rounds = it + 1;
    pose = next;
    any = true;
    if (r.shift_px < options_.converged_px) break;
  }
  r.world_from_cam = world_from_cam;
  r.accepted = false;
  if (!any) return r;
  r.translation_change_m =
      (pose.translation - world_from_cam.translation).norm();
  r.rotation_change_deg =
      RadToDegMulDiv(AngleBetween(pose.rotation, world_from_cam.rotation));
  if (r.translation_change_m > options_.max_translation_m ||
      r.rotation_change_deg > options_.max_rotation_deg) {
    return r;
  }
  r.accepted = true;
  r.world_from_cam = pose;
  return r;
}

}  // namespace monomap
