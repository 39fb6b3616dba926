#include "monomap/eval/checkerboard_accuracy.h"

#include <Eigen/Geometry>

#include <yaml-cpp/yaml.h>

#include <limits>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "monomap/util/error.h"
#include "monomap/util/file.h"

namespace monomap {

bool CheckerboardSpec::Over(const Eigen::Vector3d& x) const {
  const Eigen::Vector3d d = x - origin;
  const double u = d.dot(x_axis.normalized()) / square_m;
  const double v = d.dot(y_axis.normalized()) / square_m;
  return u >= -1.0 && u <= inner_corners_x && v >= -1.0 &&
         v <= inner_corners_y;
}
namespace {

// The texture in grey, its unseen texels (alpha 0) shown on white as a
// viewer shows a transparent PNG. The detector needs a light quiet zone
// around the board, and a plane's extent (the outline of its features) may
// stop at the last squares, since a board's blank margin has no corners.
cv::Mat GreyOnWhite(const cv::Mat& texture) {
  cv::Mat grey;
  if (texture.channels() == 1) return texture.clone();
  if (texture.channels() == 3) {
    cv::cvtColor(texture, grey, cv::COLOR_BGR2GRAY);
    return grey;
  }
  cv::cvtColor(texture, grey, cv::COLOR_BGRA2GRAY);
  for (int r = 0; r < texture.rows; ++r) {
    const cv::Vec4b* t = texture.ptr<cv::Vec4b>(r);
    uchar* g = grey.ptr<uchar>(r);
    for (int c = 0; c < texture.cols; ++c) {
      const int a = t[c][3];
      g[c] = static_cast<uchar>((g[c] * a + 255 * (255 - a) + 127) / 255);
    }
  }
  return grey;
}

// Corner errors after the rigid motion that best fits `mapped` (in the
// spec's order) to the true corners (least squares, Umeyama).
ErrorStats ShapeError(const std::vector<Eigen::Vector3d>& mapped,
                      const CheckerboardSpec& spec) {
  const int n = static_cast<int>(mapped.size());
  Eigen::Matrix3Xd from(3, n), to(3, n);
  for (int k = 0; k < n; ++k) {
    from.col(k) = mapped[k];
    to.col(k) = spec.Corner(k % spec.inner_corners_x, k / spec.inner_corners_x);
  }
  const Eigen::Matrix4d fit = Eigen::umeyama(from, to, /*with_scaling=*/false);
  std::vector<double> errors;
  for (int k = 0; k < n; ++k) {
    const Eigen::Vector3d moved =
        fit.topLeftCorner<3, 3>() * from.col(k) + fit.topRightCorner<3, 1>();
    errors.push_back((moved - to.col(k)).norm());
  }
  return ComputeErrorStats(errors);
}

}  // namespace

CheckerboardAccuracy EvaluateCheckerboard(const Map& map,
                                          const CheckerboardSpec& spec,
                                          const Sim3d& truth_from_map) {
  CheckerboardAccuracy result;
  const cv::Size pattern(spec.inner_corners_x, spec.inner_corners_y);
  for (const TexturedPlane& plane : map.planes) {
    if (plane.texture.empty()) continue;
    const cv::Mat grey = GreyOnWhite(plane.texture);
    std::vector<cv::Point2f> corners;
    std::string detector = "findChessboardCorners";
    if (!cv::findChessboardCorners(
            grey, pattern, corners,
            cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE)) {
      detector = "findChessboardCornersSB";
      corners.clear();
      if (!cv::findChessboardCornersSB(grey, pattern, corners,
                                       cv::CALIB_CB_ACCURACY)) {
        continue;
      }
    }
    cv::cornerSubPix(
        grey, corners, cv::Size(5, 5), cv::Size(-1, -1),
        cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 40,
                         0.01));
    std::vector<Eigen::Vector3d> mapped;
    for (const auto& c : corners) {
      mapped.push_back(truth_from_map.rigid *
                       (truth_from_map.scale *
                        plane.WorldFromTexture(Eigen::Vector2d(c.x, c.y))));
    }
    // OpenCV orders corners row by row along the pattern's width (x),
    // starting at any of the board's four corners (and the texture may be
    // mirrored relative to the board axes): try the four orderings and keep
    // the one with the smallest error.
    const int nx = spec.inner_corners_x, ny = spec.inner_corners_y;
    ErrorStats best;
    best.mean = std::numeric_limits<double>::infinity();
    std::vector<Eigen::Vector3d> best_order;
    for (int flip = 0; flip < 4; ++flip) {
      std::vector<double> errors;
      std::vector<Eigen::Vector3d> order(mapped.size());
      for (int k = 0; k < static_cast<int>(mapped.size()); ++k) {
        int i = k % nx, j = k / nx;
        if (flip & 1) i = nx - 1 - i;
        if (flip & 2) j = ny - 1 - j;
        errors.push_back((mapped[k] - spec.Corner(i, j)).norm());
        order[j * nx + i] = mapped[k];
      }
      const ErrorStats e = ComputeErrorStats(errors);
      if (e.mean < best.mean) {
        best = e;
        best_order = order;
      }
    }
    mapped = best_order;
    result.shape_error_m = ShapeError(mapped, spec);
    result.found = true;
    result.plane_id = plane.id;
    result.corners_found = static_cast<int>(mapped.size());
    result.detector = detector;
    result.error_m = best;
    result.corners_in_world = mapped;
    return result;
  }
  return result;
}

CheckerboardSpec ReadCheckerboardYaml(const std::filesystem::path& path) {
  YAML::Node root;
  try {
    root = YAML::Load(ReadFileToString(path));
  } catch (const YAML::Exception& e) {
    throw InputError(path.string(), e.mark.line + 1,
                     "malformed YAML: " + e.msg);
  }
  // Subscripting a scalar or a list throws; check the kinds first.
  const YAML::Node b = root.IsMap() ? root["chessboard"] : YAML::Node();
  if (!b || !b.IsMap()) {
    throw InputError(path.string(), "chessboard", "missing or not a map");
  }
  CheckerboardSpec spec;
  try {
    spec.inner_corners_x = b["inner_corners_x"].as<int>();
    spec.inner_corners_y = b["inner_corners_y"].as<int>();
    spec.square_m = b["square_m"].as<double>();
    auto vec = [&](const char* key, Eigen::Vector3d* v) {
      if (!b[key]) return;
      const auto values = b[key].as<std::vector<double>>();
      if (values.size() != 3) {
        throw InputError(path.string(), std::string("chessboard.") + key,
                         "expected 3 numbers");
      }
      *v = Eigen::Vector3d(values[0], values[1], values[2]);
    };
    vec("origin", &spec.origin);
    vec("x_axis", &spec.x_axis);
    vec("y_axis", &spec.y_axis);
  } catch (const YAML::Exception& e) {
    throw InputError(path.string(), "chessboard", e.msg);
  }
  if (spec.inner_corners_x < 2 || spec.inner_corners_y < 2 ||
      spec.square_m <= 0) {
    throw InputError(path.string(), "chessboard", "invalid board size");
  }
  return spec;
}

}  // namespace monomap
