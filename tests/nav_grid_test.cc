// The navigation grid of a simulated world's true planes, read back from
// the written map.yaml + map.pgm, against the world's true walls.
#include <gtest/gtest.h>

#include <filesystem>

#include "monomap/io/nav_grid_export.h"
#include "monomap/sim/world.h"
#include "monomap/util/error.h"
#include "nav_grid_truth.h"

namespace monomap {
namespace {

namespace fs = std::filesystem;

TEST(NavGridTest, TrueWallsOfEveryWorldWithinOneCell) {
  for (const std::string& name : WorldNames()) {
    for (double resolution : {0.05, 0.1}) {
      SCOPED_TRACE(name + " at " + std::to_string(resolution) + " m");
      const World world = MakeWorld(name, 1, 20.0);
      Map map;
      map.planes = world.planes;
      NavGridOptions options;
      options.resolution_m = resolution;
      NavGridReport report;
      const NavGrid made = MakeNavGrid(map, options, &report);
      const fs::path dir = fs::temp_directory_path() / "monomap_nav_grid_test";
      fs::remove_all(dir);
      WriteNavGrid(dir, made, options);
      // Measure what a map_server user gets: the files.
      const NavGrid grid = ReadNavGrid(dir / "map.yaml");
      ASSERT_EQ(grid.cells.size(), made.cells.size());
      EXPECT_EQ(cv::norm(grid.cells, made.cells, cv::NORM_INF), 0.0);
      EXPECT_EQ(report.num_floor_planes, 1);
      EXPECT_GT(report.num_occupied, 0);

      const NavGridFigures f =
          MeasureNavGrid(grid, NavGridTruth(world.planes, options));
      std::printf(
          "%-10s %.2f m: wall cells <= %.2f cells from truth, %.1f%% "
          "of wall length covered, %.1f%% of interior floor free, "
          "%.2f%% free cells off the floor\n",
          name.c_str(), resolution, f.max_wall_cell_distance_cells,
          100 * f.wall_length_covered, 100 * f.interior_floor_free,
          100 * f.free_outside_floor);
      EXPECT_LE(f.max_wall_cell_distance_cells, 1.0);
      EXPECT_GE(f.wall_length_covered, 0.99);
      EXPECT_GE(f.interior_floor_free, 0.99);
      EXPECT_EQ(f.free_outside_floor, 0.0);
    }
  }
}

TEST(NavGridTest, BandSelectsObstacles) {
  // The room's metal cabinet is 1.8 m tall, the other boxes 0.6 and 0.75 m:
  // a band above 0.8 m keeps walls and the cabinet only.
  const World world = MakeWorld("room", 1, 20.0);
  Map map;
  map.planes = world.planes;
  NavGridOptions low, high;
  high.min_z_m = 0.8;
  NavGridReport r_low, r_high;
  MakeNavGrid(map, low, &r_low);
  MakeNavGrid(map, high, &r_high);
  // 4 walls, 5 faces of each low box and the cabinet's 4 sides (its top is
  // above the band) in the default band; 4 walls + 4 cabinet sides above
  // 0.8 m.
  EXPECT_EQ(r_low.num_obstacle_planes, 18);
  EXPECT_EQ(r_high.num_obstacle_planes, 8);
  EXPECT_GT(r_high.num_free, r_low.num_free);
}

TEST(NavGridTest, BadOptionsAndEmptyMapsAreRejected) {
  NavGridOptions o;
  o.min_z_m = 2.0;
  EXPECT_THROW(o.Check(), OptionsError);
  o = NavGridOptions();
  o.resolution_m = 0;
  EXPECT_THROW(o.Check(), OptionsError);
  o = NavGridOptions();
  o.free_thresh = 0.3;  // unknown pixels would read as free
  EXPECT_THROW(o.Check(), OptionsError);
  EXPECT_THROW(MakeNavGrid(Map(), NavGridOptions()), StageError);
  const fs::path dir = fs::temp_directory_path() / "monomap_nav_grid_bad";
  fs::create_directories(dir);
  std::FILE* f = std::fopen((dir / "map.yaml").c_str(), "w");
  std::fputs("image: map.pgm\nresolution: 0.05\n", f);
  std::fclose(f);
  try {
    ReadNavGrid(dir / "map.yaml");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("origin"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace monomap
