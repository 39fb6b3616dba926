// The outline of a set of occupied grid cells as a polygon in plane
// coordinates: how a plane segment is bounded by its points' occupancy
// grid (plane fitting) and by the cells its images explain (growth).
#pragma once

#include <opencv2/core.hpp>

#include "monomap/geometry/polygon.h"

namespace monomap {

// Outer outline of the set (non-zero) cells; the grid's cell (r, c) covers
// plane coordinates lo + cell * (c - margin, r - margin) and one cell
// more. Only the largest connected set is outlined. Empty if there is none
// worth a polygon.
Polygon2d OutlineOfCells(const cv::Mat1b& cells, const Eigen::Vector2d& lo,
                         double cell, int margin);

}  // namespace monomap
