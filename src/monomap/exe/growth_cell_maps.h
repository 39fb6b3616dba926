// build --debug-growth DIR: plane growth's per-cell verdicts
// (PlaneGrowthOptions::keep_cell_maps) as one image per plane and a JSON
// summary, to see why a plane stopped where it did.
#pragma once

#include <filesystem>

#include "monomap/planes/plane_growth.h"

namespace monomap {

// Writes DIR/plane_<id>.png for every plane with a cell map (4x4 pixels
// per cell, the plane's t axis up; colour = verdict, bright where the cell
// is in the grown polygon, dim elsewhere, a white corner where it is in
// the fitted polygon) and DIR/cells.json (per plane: cell size and counts
// per verdict, over all cells and over the grown ones; the colour legend).
// DIR is created and marked as a "growth-debug" output.
void WriteGrowthCellMaps(const std::filesystem::path& dir,
                         const PlaneGrowthReport& report);

}  // namespace monomap
