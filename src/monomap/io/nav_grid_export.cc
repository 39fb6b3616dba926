#include "monomap/io/nav_grid_export.h"

#include <yaml-cpp/yaml.h>

#include <Eigen/Geometry>
#include <charconv>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <vector>

#include "monomap/geometry/polygon.h"
#include "monomap/util/angles.h"
#include "monomap/util/error.h"
#include "monomap/util/file.h"

namespace monomap {

namespace {

namespace fs = std::filesystem;

constexpr const char* kPgmName = "map.pgm";
constexpr const char* kYamlName = "map.yaml";
// map_server's conventional pixel values (negate 0).
constexpr uint8_t kPgmOccupied = 0;
constexpr uint8_t kPgmFree = 254;
constexpr uint8_t kPgmUnknown = 205;
// Samples per cell side when rasterizing a plane: three keep a thin wall
// a connected line of cells.
constexpr double kSamplesPerCell = 3.0;

enum class PlaneRole { kIgnored, kFloor, kObstacle };

PlaneRole Classify(const TexturedPlane& p, const NavGridOptions& o) {
  if (p.polygon.size() < 3) return PlaneRole::kIgnored;
  double z_lo = INFINITY, z_hi = -INFINITY;
  for (const Eigen::Vector2d& st : p.polygon) {
    const double z = p.frame.ToWorld(st).z();
    z_lo = std::min(z_lo, z);
    z_hi = std::max(z_hi, z);
  }
  const bool horizontal = std::abs(p.plane.normal.z()) >=
                          std::cos(DegToRadMulDiv(o.horizontal_max_tilt_deg));
  if (horizontal && z_hi < o.min_z_m) return PlaneRole::kFloor;
  if (z_hi >= o.min_z_m && z_lo <= o.max_z_m) return PlaneRole::kObstacle;
  return PlaneRole::kIgnored;
}

// Calls visit(x_in_world) for points on a grid of spacing `step` over the
// plane's polygon.
template <typename Visit>
void SamplePlane(const TexturedPlane& p, double step, Visit visit) {
  Eigen::Vector2d lo, hi;
  PolygonBounds(p.polygon, &lo, &hi);
  const int ns = static_cast<int>(std::ceil((hi.x() - lo.x()) / step));
  const int nt = static_cast<int>(std::ceil((hi.y() - lo.y()) / step));
  for (int j = 0; j < nt; ++j) {
    for (int i = 0; i < ns; ++i) {
      const Eigen::Vector2d st = lo + step * Eigen::Vector2d(i + 0.5, j + 0.5);
      if (PointInPolygon(p.polygon, st)) visit(p.frame.ToWorld(st));
    }
  }
}

// Roles of all planes; the xy extent of the used ones and their counts.
std::vector<PlaneRole> ClassifyPlanes(const Map& map, const NavGridOptions& o,
                                      Eigen::AlignedBox2d* extent,
                                      NavGridReport* r) {
  std::vector<PlaneRole> roles;
  for (const TexturedPlane& p : map.planes) {
    roles.push_back(Classify(p, o));
    if (roles.back() == PlaneRole::kIgnored) continue;
    (roles.back() == PlaneRole::kFloor ? r->num_floor_planes
                                       : r->num_obstacle_planes)++;
    for (const Eigen::Vector2d& st : p.polygon) {
      extent->extend(p.frame.ToWorld(st).head<2>());
    }
  }
  return roles;
}

void CountCells(const NavGrid& grid, NavGridReport* r) {
  r->width = grid.cells.cols;
  r->height = grid.cells.rows;
  for (uint8_t v : grid.cells) {
    const NavCell c = static_cast<NavCell>(v);
    (c == NavCell::kFree       ? r->num_free
     : c == NavCell::kOccupied ? r->num_occupied
                               : r->num_unknown)++;
  }
}

// Marks floor samples free, then obstacle samples inside the band occupied.
void Rasterize(const Map& map, const std::vector<PlaneRole>& roles,
               const NavGridOptions& options, NavGrid* grid) {
  auto mark = [&](const Eigen::Vector3d& x, NavCell value) {
    const int c = static_cast<int>(
        std::floor((x.x() - grid->origin.x()) / grid->resolution_m));
    const int row = static_cast<int>(
        std::floor((x.y() - grid->origin.y()) / grid->resolution_m));
    if (c < 0 || row < 0 || c >= grid->cells.cols || row >= grid->cells.rows) {
      return;
    }
    grid->cells(row, c) = static_cast<uint8_t>(value);
  };
  const double step = grid->resolution_m / kSamplesPerCell;
  // Floor first, obstacles over it.
  for (PlaneRole role : {PlaneRole::kFloor, PlaneRole::kObstacle}) {
    for (size_t i = 0; i < map.planes.size(); ++i) {
      if (roles[i] != role) continue;
      SamplePlane(map.planes[i], step, [&](const Eigen::Vector3d& x) {
        if (role == PlaneRole::kFloor) {
          mark(x, NavCell::kFree);
        } else if (x.z() >= options.min_z_m && x.z() <= options.max_z_m) {
          mark(x, NavCell::kOccupied);
        }
      });
    }
  }
}

std::string Number(double v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof(buf), v);
  return std::string(buf, r.ptr);
}

}  // namespace

void NavGridOptions::Check() const {
  CheckOption(resolution_m > 0 && std::isfinite(resolution_m),
              "nav_grid.resolution_m", "must be > 0");
  CheckOption(
      std::isfinite(min_z_m) && std::isfinite(max_z_m) && min_z_m < max_z_m,
      "nav_grid.min_z_m", "the height band needs min_z_m < max_z_m");
  CheckOption(horizontal_max_tilt_deg >= 0 && horizontal_max_tilt_deg < 90,
              "nav_grid.horizontal_max_tilt_deg", "must be in [0, 90)");
  CheckOption(margin_m >= 0 && std::isfinite(margin_m), "nav_grid.margin_m",
              "must be >= 0");
  CheckOption(
      free_thresh >= 0 && free_thresh < occupied_thresh && occupied_thresh <= 1,
      "nav_grid.free_thresh", "needs 0 <= free_thresh < occupied_thresh <= 1");
  // The fixed PGM values must read back as what they mean.
  CheckOption((255.0 - kPgmUnknown) / 255.0 >= free_thresh &&
                  (255.0 - kPgmUnknown) / 255.0 <= occupied_thresh &&
                  (255.0 - kPgmFree) / 255.0 < free_thresh,
              "nav_grid.free_thresh",
              "must be in (0.004, 0.196] so free (254) and unknown (205) "
              "pixels read back as such");
  CheckOption(max_cells_per_side > 0, "nav_grid.max_cells_per_side",
              "must be > 0");
}

NavGrid MakeNavGrid(const Map& map, const NavGridOptions& options,
                    NavGridReport* report) {
  options.Check();
  NavGridReport r;
  Eigen::AlignedBox2d extent;
  const std::vector<PlaneRole> roles =
      ClassifyPlanes(map, options, &extent, &r);
  const Eigen::Vector2d lo = extent.min(), hi = extent.max();
  if (r.num_floor_planes + r.num_obstacle_planes == 0) {
    throw StageError(
        "navigation grid: no floor plane below z = " + Number(options.min_z_m) +
        " m and no plane in the height band");
  }
  NavGrid grid;
  const double res = options.resolution_m;
  grid.resolution_m = res;
  grid.origin = ((lo.array() - options.margin_m) / res).floor() * res;
  const Eigen::Vector2d size =
      (hi.array() + options.margin_m - grid.origin.array()) / res;
  const int cols = static_cast<int>(std::ceil(size.x()));
  const int rows = static_cast<int>(std::ceil(size.y()));
  if (cols > options.max_cells_per_side || rows > options.max_cells_per_side) {
    throw StageError("navigation grid: " + std::to_string(cols) + " x " +
                     std::to_string(rows) +
                     " cells exceeds max_cells_per_side " +
                     std::to_string(options.max_cells_per_side));
  }
  grid.cells = cv::Mat1b(std::max(rows, 1), std::max(cols, 1),
                         static_cast<uint8_t>(NavCell::kUnknown));
  Rasterize(map, roles, options, &grid);
  CountCells(grid, &r);
  if (report) *report = r;
  return grid;
}

void WriteNavGrid(const fs::path& dir, const NavGrid& grid,
                  const NavGridOptions& options) {
  options.Check();
  cv::Mat1b image(grid.cells.rows, grid.cells.cols);
  for (int row = 0; row < grid.cells.rows; ++row) {
    for (int c = 0; c < grid.cells.cols; ++c) {
      const NavCell v = grid.At(c, row);
      // Image row 0 is the top of the map: the highest y.
      image(grid.cells.rows - 1 - row, c) = v == NavCell::kOccupied
                                                ? kPgmOccupied
                                            : v == NavCell::kFree ? kPgmFree
                                                                  : kPgmUnknown;
    }
  }
  std::vector<uchar> pgm;
  if (!cv::imencode(".pgm", image, pgm, {cv::IMWRITE_PXM_BINARY, 1})) {
    throw OutputError((dir / kPgmName).string() + ": cannot encode PGM");
  }
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw OutputError(dir.string() + ": " + ec.message());
  const std::string yaml =
      std::string("# ROS map_server occupancy grid written by monomap\n") +
      "image: " + kPgmName +
      "\nmode: trinary\nresolution: " + Number(grid.resolution_m) +
      "\norigin: [" + Number(grid.origin.x()) + ", " + Number(grid.origin.y()) +
      ", 0.0]\nnegate: 0\noccupied_thresh: " + Number(options.occupied_thresh) +
      "\nfree_thresh: " + Number(options.free_thresh) + "\n";
  WriteFileAtomic(dir / kPgmName, std::string(pgm.begin(), pgm.end()));
  WriteFileAtomic(dir / kYamlName, yaml);
}

NavGrid ReadNavGrid(const fs::path& yaml_path) {
  const std::string file = yaml_path.string();
  YAML::Node root;
  try {
    root = YAML::Load(ReadFileToString(yaml_path));
  } catch (const YAML::Exception& e) {
    throw InputError(file, e.mark.line + 1, e.msg);
  }
  auto field = [&](const char* name) {
    if (!root.IsMap() || !root[name]) {
      throw InputError(file, name, "missing");
    }
    return root[name];
  };
  NavGrid grid;
  double occupied = 0, free = 0;
  int negate = 0;
  std::vector<double> origin;
  std::string image;
  try {
    image = field("image").as<std::string>();
    grid.resolution_m = field("resolution").as<double>();
    origin = field("origin").as<std::vector<double>>();
    negate = field("negate").as<int>();
    occupied = field("occupied_thresh").as<double>();
    free = field("free_thresh").as<double>();
  } catch (const YAML::Exception& e) {
    throw InputError(file, e.mark.line + 1, "bad value: " + e.msg);
  }
  if (origin.size() != 3) throw InputError(file, "origin", "needs [x, y, yaw]");
  if (origin[2] != 0.0) {
    throw InputError(file, "origin",
                     "a rotated grid (yaw != 0) is not supported");
  }
  if (!(grid.resolution_m > 0))
    throw InputError(file, "resolution", "must be > 0");
  grid.origin = {origin[0], origin[1]};
  const fs::path image_path = fs::path(image).is_absolute()
                                  ? fs::path(image)
                                  : yaml_path.parent_path() / image;
  const cv::Mat1b pixels =
      cv::imread(image_path.string(), cv::IMREAD_GRAYSCALE);
  if (pixels.empty()) throw InputError(file, "image", "cannot read " + image);
  grid.cells.create(pixels.rows, pixels.cols);
  for (int row = 0; row < pixels.rows; ++row) {
    for (int c = 0; c < pixels.cols; ++c) {
      const double v = pixels(pixels.rows - 1 - row, c);
      const double p = negate ? v / 255.0 : (255.0 - v) / 255.0;
      grid.cells(row, c) =
          static_cast<uint8_t>(p > occupied ? NavCell::kOccupied
                               : p < free   ? NavCell::kFree
                                            : NavCell::kUnknown);
    }
  }
  return grid;
}

}  // namespace monomap
