#include "monomap/planes/cell_outline.h"

#include <gtest/gtest.h>

#include <cmath>

#include "monomap/util/error.h"

namespace monomap {
namespace {

// Share of the square [x0, x1] x [y0, y1] inside the polygon (1 mm samples).
double Covered(const Polygon2d& poly, double x0, double x1, double y0,
               double y1) {
  int in = 0, all = 0;
  for (double x = x0 + 0.0005; x < x1; x += 0.001) {
    for (double y = y0 + 0.0005; y < y1; y += 0.001) {
      ++all;
      in += PointInPolygon(poly, {x, y}) ? 1 : 0;
    }
  }
  return static_cast<double>(in) / all;
}

// A triangle across a 10 cm grid, with two cells added below its base and
// one of its cells removed: the outline follows the triangle's own edges
// (within a third of a cell), not the cells whose centres it holds.
TEST(OutlineOfPolygonAndCells, KeepsThePolygonsShapeAndAddsTheCells) {
  const double cell = 0.1;
  const Eigen::Vector2d lo(0, 0);
  // Inside where (x - 0.1) / 0.68 + (y - 0.1) / 0.48 <= 1.
  const Polygon2d triangle = {{0.1, 0.1}, {0.78, 0.1}, {0.1, 0.58}};
  cv::Mat1b added = cv::Mat1b::zeros(8, 10), removed = cv::Mat1b::zeros(8, 10);
  added(0, 3) = added(0, 4) = 1;  // x 0.3-0.5, y 0-0.1
  removed(1, 1) = 1;              // x 0.1-0.2, y 0.1-0.2
  const Polygon2d poly =
      OutlineOfPolygonAndCells(triangle, added, removed, lo, cell, 3);
  ASSERT_GE(poly.size(), 3u);
  const double triangle_area = 0.5 * 0.68 * 0.48;
  const double expected = triangle_area + 0.02 - 0.01;
  EXPECT_NEAR(std::abs(PolygonArea(poly)), expected, 0.05 * expected);
  // Inside the triangle and the added cells, off the removed cell.
  EXPECT_GT(Covered(poly, 0.25, 0.35, 0.2, 0.3), 0.99);
  EXPECT_GT(Covered(poly, 0.31, 0.49, 0.01, 0.09), 0.99);
  EXPECT_LT(Covered(poly, 0.11, 0.19, 0.11, 0.19), 0.01);
  // The corner of cell (x 0.3-0.4, y 0.3-0.4) beyond the hypotenuse stays
  // out, though the cell's centre is inside.
  EXPECT_LT(Covered(poly, 0.38, 0.4, 0.38, 0.4), 0.5);
}

TEST(OutlineOfPolygonAndCells, RejectsGridsOfDifferentSizes) {
  EXPECT_THROW(
      OutlineOfPolygonAndCells({{0, 0}, {1, 0}, {0, 1}}, cv::Mat1b::zeros(2, 2),
                               cv::Mat1b::zeros(3, 2), {0, 0}, 0.1, 3),
      StageError);
}

}  // namespace
}  // namespace monomap
