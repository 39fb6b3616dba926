// Builds a simulated room, makes its navigation grid and prints what it
// got: the smallest program that uses monomap's headers and libraries.
// Exit status 0 only if the grid has free and occupied cells.
#include <cstdio>

#include "monomap/io/nav_grid_export.h"
#include "monomap/sim/world.h"
#include "monomap/version.h"

int main() {
  const monomap::World world = monomap::MakeWorld("room", 1, 20.0);
  monomap::Map map;
  map.planes = world.planes;
  monomap::NavGridReport report;
  monomap::MakeNavGrid(map, monomap::NavGridOptions(), &report);
  std::printf("monomap %s (%s): room grid %d x %d, %d free, %d occupied\n",
              monomap::kVersion, monomap::kGitCommit, report.width,
              report.height, report.num_free, report.num_occupied);
  return report.num_free > 0 && report.num_occupied > 0 ? 0 : 1;
}
