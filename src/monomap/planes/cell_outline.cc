#include "monomap/planes/cell_outline.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "monomap/util/error.h"

namespace monomap {

Polygon2d OutlineOfCells(const cv::Mat1b& cells, const Eigen::Vector2d& lo,
                         double cell, int margin) {
  // Contours pass through boundary pixel centres; upsampling the cells
  // puts them 1/8 cell inside the occupied area instead of 1/2.
  constexpr int kUp = 4;
  cv::Mat1b mask;
  cv::resize(cells, mask, {}, kUp, kUp, cv::INTER_NEAREST);
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(mask, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
  if (contours.empty()) return {};
  const auto largest = std::max_element(
      contours.begin(), contours.end(), [](const auto& a, const auto& b) {
        return std::abs(cv::contourArea(a)) < std::abs(cv::contourArea(b));
      });
  std::vector<cv::Point> simple;
  cv::approxPolyDP(*largest, simple, 0.5 * kUp, true);
  if (simple.size() < 3) return {};
  // The contour runs through the centres of the boundary pixels: move each
  // vertex half a pixel outwards (miter offset) onto the pixel edges.
  Polygon2d px;
  for (const auto& q : simple) px.emplace_back(q.x + 0.5, q.y + 0.5);
  const double orientation = PolygonArea(px) > 0 ? 1.0 : -1.0;
  const size_t m = px.size();
  Polygon2d poly;
  for (size_t i = 0; i < m; ++i) {
    const Eigen::Vector2d& prev = px[(i + m - 1) % m];
    const Eigen::Vector2d& next = px[(i + 1) % m];
    const Eigen::Vector2d d1 = (px[i] - prev).normalized();
    const Eigen::Vector2d d2 = (next - px[i]).normalized();
    const Eigen::Vector2d n1 = orientation * Eigen::Vector2d(d1.y(), -d1.x());
    const Eigen::Vector2d n2 = orientation * Eigen::Vector2d(d2.y(), -d2.x());
    const double denom = std::max(1.0 + n1.dot(n2), 0.25);  // cap spikes
    const Eigen::Vector2d q = px[i] + 0.5 * (n1 + n2) / denom;
    poly.emplace_back(lo.x() + (q.x() / kUp - margin) * cell,
                      lo.y() + (q.y() / kUp - margin) * cell);
  }
  if (PolygonArea(poly) < 0) std::reverse(poly.begin(), poly.end());
  return poly;
}

Polygon2d OutlineOfPolygonAndCells(const Polygon2d& polygon,
                                   const cv::Mat1b& added,
                                   const cv::Mat1b& removed,
                                   const Eigen::Vector2d& lo, double cell,
                                   int fine) {
  if (added.size() != removed.size() || fine < 1 || !(cell > 0)) {
    throw StageError(
        "OutlineOfPolygonAndCells: grids of different sizes, fine < 1 or "
        "cell <= 0");
  }
  const double step = cell / fine;
  cv::Mat1b cells(added.rows * fine, added.cols * fine, uint8_t{0});
  // The polygon is tested only over its bounds (exact centre-in-polygon:
  // cv::fillPoly also fills the pixels its edges touch).
  Eigen::Vector2d plo(0, 0), phi(-1, -1);
  if (!polygon.empty()) PolygonBounds(polygon, &plo, &phi);
  const int c0 =
      std::max(0, static_cast<int>(std::floor((plo.x() - lo.x()) / step)));
  const int r0 =
      std::max(0, static_cast<int>(std::floor((plo.y() - lo.y()) / step)));
  const int c1 = std::min(
      cells.cols - 1, static_cast<int>(std::ceil((phi.x() - lo.x()) / step)));
  const int r1 = std::min(
      cells.rows - 1, static_cast<int>(std::ceil((phi.y() - lo.y()) / step)));
  for (int r = r0; r <= r1; ++r) {
    for (int c = c0; c <= c1; ++c) {
      if (removed(r / fine, c / fine)) continue;
      const Eigen::Vector2d st = lo + step * Eigen::Vector2d(c + 0.5, r + 0.5);
      cells(r, c) = PointInPolygon(polygon, st) ? 1 : 0;
    }
  }
  cv::Mat1b fine_added;  // nearest at an integer factor: fine r is r / fine
  cv::resize(added, fine_added, cells.size(), 0, 0, cv::INTER_NEAREST);
  cells.setTo(1, fine_added);
  return OutlineOfCells(cells, lo, step, 0);
}

}  // namespace monomap
