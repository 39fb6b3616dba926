#include "monomap/tracking/pyramidal_lk.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <opencv2/video/tracking.hpp>
#include <string>

#include "monomap/util/error.h"

namespace monomap {

void PyrLkOptions::Check() const {
  CheckOption(window >= 3 && window % 2 == 1, "lk.window",
              "must be odd and >= 3");
  CheckOption(levels >= 0, "lk.levels", "must be >= 0");
  CheckOption(max_iterations >= 1, "lk.max_iterations", "must be >= 1");
  CheckOption(epsilon > 0, "lk.epsilon", "must be > 0");
  CheckOption(min_eigen_threshold >= 0, "lk.min_eigen_threshold",
              "must be >= 0");
  CheckOption(chunk >= 1, "lk.chunk", "must be >= 1");
}

void BuildLkPyramid(const cv::Mat& grey, const PyrLkOptions& options,
                    std::vector<cv::Mat>* pyramid) {
  cv::buildOpticalFlowPyramid(grey, *pyramid,
                              cv::Size(options.window, options.window),
                              options.levels, /*withDerivatives=*/true);
}

void PyramidalLk(const std::vector<cv::Mat>& from,
                 const std::vector<cv::Mat>& to,
                 const std::vector<cv::Point2f>& points_in,
                 std::vector<cv::Point2f>* points_out,
                 std::vector<uchar>* status, std::vector<float>* error,
                 const PyrLkOptions& options) {
  options.Check();
  const size_t n = points_in.size();
  if (options.use_initial_guess && points_out->size() != n) {
    throw OptionsError("PyramidalLk: use_initial_guess needs " +
                       std::to_string(n) + " initial points, got " +
                       std::to_string(points_out->size()));
  }
  if (!options.use_initial_guess) points_out->assign(n, cv::Point2f());
  status->assign(n, 0);
  error->assign(n, 0.0f);
  const cv::Size window(options.window, options.window);
  const cv::TermCriteria criteria(
      cv::TermCriteria::COUNT | cv::TermCriteria::EPS, options.max_iterations,
      options.epsilon);
  const int flags =
      options.use_initial_guess ? cv::OPTFLOW_USE_INITIAL_FLOW : 0;
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, n, static_cast<size_t>(options.chunk)),
      [&](const tbb::blocked_range<size_t>& r) {
        const std::vector<cv::Point2f> in(points_in.begin() + r.begin(),
                                          points_in.begin() + r.end());
        std::vector<cv::Point2f> out(points_out->begin() + r.begin(),
                                     points_out->begin() + r.end());
        std::vector<uchar> st;
        std::vector<float> err;
        cv::calcOpticalFlowPyrLK(from, to, in, out, st, err, window,
                                 options.levels, criteria, flags,
                                 options.min_eigen_threshold);
        std::copy(out.begin(), out.end(), points_out->begin() + r.begin());
        std::copy(st.begin(), st.end(), status->begin() + r.begin());
        std::copy(err.begin(), err.end(), error->begin() + r.begin());
      });
}

}  // namespace monomap
