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

// The outline of `polygon`, less the grid cells `removed`, joined with the
// grid cells `added` (non-zero cells of two grids of the same size; cell
// (r, c) covers lo + cell * (c, r) and one cell more), traced on a grid
// `fine` times finer: the polygon keeps its own shape within cell / fine
// where it is not removed, rather than being redrawn as whole cells (which
// widens it by up to half a cell). Only the largest connected part is
// outlined; empty if there is none worth a polygon.
Polygon2d OutlineOfPolygonAndCells(const Polygon2d& polygon,
                                   const cv::Mat1b& added,
                                   const cv::Mat1b& removed,
                                   const Eigen::Vector2d& lo, double cell,
                                   int fine);

}  // namespace monomap
