// Growing plane polygons over the image regions their plane explains
// (issue 18, item 1). A plane fitted to triangulated points is bounded by
// its points, but a wall or a floor extends over stretches where tracking
// found few good points: plain paint, grazing views, short tracks. There
// the images still say where the plane is: a patch of the plane seen from
// several views of enough parallax looks the same in all of them only if
// the surface really lies on the plane there (photo-consistency through
// the plane-induced homography).
//
// Growth works on a grid of cells in each segment's plane, starting from
// its polygon. A cell joins the segment when it is seen by enough views
// with enough parallax, not hidden by another plane, and
//  - textured: its patch correlates across the views (NCC), and its
//    texture changes along the direction in which a surface off the plane
//    would misregister them (an edge along the direction of travel
//    correlates through any plane: the aperture problem), or
//  - plain: the views agree on its brightness, and it is at most
//    max_plain_run cells from a cell with texture evidence (or the
//    original polygon): plain paint agrees from every view, wherever the
//    plane is, so only texture proves the plane and plain cells only bridge.
// The fitted polygon itself loses the cells that every view sees only
// through a crossing plane: a misplaced point can pull a floor's polygon
// behind a wall's foot, where no image shows it.
// Free space bounds it: a cell crossed by the viewing rays of landmarks
// that lie behind the plane is empty (the views looked through it). And a
// cell over a parallel plane's polygon, a few cells from it, is that
// plane's: photo-consistency cannot tell a keyboard's plane from its desk's.
//
// The same photometric test checks plane hypotheses (plane_hypotheses.h),
// planes that a few landmarks suggest: one becomes a segment only where
// the images confirm it, and over a parallel plane's polygon only where it
// explains the images clearly better than that plane.
#pragma once

#include <functional>
#include <vector>

#include <opencv2/core.hpp>

#include "monomap/camera/camera.h"
#include "monomap/geometry/rigid3.h"
#include "monomap/map/map.h"

namespace monomap {

struct PlaneGrowthOptions {
  // Grow polygons at all (the polygon before growth is kept as
  // PlaneSegment::landmark_polygon, which localization renders).
  bool enabled = true;
  // Cell side in image pixels at the plane's median view resolution, so the
  // grid is scale-free (a desk and a hallway get the same image support).
  double cell_px = 12.0;
  // Samples per cell side (samples^2 per cell and view): about one per
  // 1.5 image pixels, so that a surface off the plane shifts the pattern.
  int samples_per_side = 8;
  // Growth reaches at most this many cells beyond the polygon's bounds.
  int max_growth_cells = 40;
  // Frames used as views, evenly spread over the sequence.
  int max_views = 40;
  // A cell needs at least this many views that see all its samples.
  int min_views = 3;
  // ... whose rays to the cell's centre span at least this angle (deg):
  // without parallax every plane hypothesis is photo-consistent.
  double min_parallax_deg = 4.0;
  // The same bar for plain cells (deg). Their test (equal brightness) does
  // not use parallax, and they join only between proofs (max_plain_run,
  // plain_between_proofs), so 0 is sound; it stays opt-in for now
  // (docs/design-notes.md, "Planes").
  double min_plain_parallax_deg = 4.0;
  // Views at grazing angles (|cos(ray, normal)| below this) do not count.
  double min_cos_view_angle = 0.15;
  // A view's patch is textured if its standard deviation (grey levels) is
  // at least this; a cell is textured if most of its views are.
  double min_texture_std = 6.0;
  // Textured cells: median over the views of the NCC of each view's patch
  // with that of the view of the most parallax from it must reach this.
  double min_ncc = 0.8;
  // A textured cell proves nothing if its texture hardly changes along the
  // direction in which a surface off the plane would misregister the views
  // (an edge along the direction of travel matches through any plane): its
  // patch moved along that direction must decorrelate at least
  // aperture_max_ratio times as much as moved across it.
  bool aperture_test = true;
  // See aperture_test (1 - NCC of the moved patch, along over across).
  double aperture_max_ratio = 0.25;
  // The move of aperture_test, in samples (of samples_per_side per cell).
  double aperture_shift_samples = 2.0;
  // Plain cells: every view's mean within this fraction of the median
  // mean (noise and what exposure compensation leaves stay within it).
  double max_plain_brightness_diff = 0.12;
  // Divide each view's brightness by its exposure gain relative to the
  // other views before the plain test: auto-exposure brightens and darkens
  // whole frames, which the test would otherwise take for a surface that
  // differs between the views. Gains from the tracked features
  // (EstimateExposureGains in plane_growth.cc).
  bool compensate_exposure = true;
  // Keep every grid cell's verdict per plane (PlaneGrowthStats::cell_map),
  // for diagnosis (build --debug-growth): judging every cell costs time.
  bool keep_cell_maps = false;
  // Plain cells may extend at most this many cells from texture evidence.
  int max_plain_run = 8;
  // ... and must lie within the convex hull of the fitted polygon and the
  // textured cells: they fill between proofs, never extend past them.
  bool plain_between_proofs = true;
  // A cell crossed by the viewing rays of at least this many landmarks
  // behind the plane is free space.
  int min_carving_landmarks = 2;
  // A landmark is behind the plane if it lies farther than this beyond it:
  // max(carve_margin_factor x the plane's cell side, its own 3-sigma
  // uncertainty along the normal).
  double carve_margin_factor = 0.5;
  // Observations per landmark whose rays carve (evenly spread).
  int max_carving_rays = 5;
  // Another plane hides a cell from a view if the ray meets it within this
  // many of its cells outside its polygon: planes that grow too, and their
  // extensions where they meet, still block the views.
  double occluder_dilation_cells = 2.0;
  // A cell within this many cells of a parallel plane (normals within
  // layer_max_angle_deg) over that plane's polygon belongs to that plane:
  // a keyboard does not grow over its desk, nor a wall over a door leaf
  // recessed in it, whose images it would explain almost as well.
  double layer_cells = 3.0;
  // See layer_cells.
  double layer_max_angle_deg = 10.0;
  // Leave out the fitted polygon's cells that every view having them in its
  // image sees through another plane meeting this one: no image shows them,
  // so only a misplaced point can have put them there ...
  bool drop_hidden_cells = true;
  // ... through a plane of at least this many of its own cells: one smaller
  // than a few cells in the images (12 px each) is too little to trust.
  double min_occluder_cells = 4.0;
  // Holes and notches up to this many cells are closed in the outline.
  int close_cells = 1;
  // Keep the fitted polygon's own outline and add the grown cells to it,
  // rather than redraw the whole polygon as growth's cells.
  bool keep_fitted_outline = true;
  // A plane hypothesis (plane_hypotheses.h) is kept when at least this
  // many cells over its landmarks' hull correlate across the views ...
  int hypothesis_min_textured_cells = 4;
  // ... and they are at least this share of the cells there whose texture
  // was judged (correlating or not): a plane through clutter or a few cm
  // off the surface misregisters the views.
  double hypothesis_min_textured_fraction = 0.6;
  // A hypothesis' cell over a parallel plane's polygon (see layer_cells)
  // is its own only if its NCC beats that plane's by this much.
  double hypothesis_min_ncc_gain = 0.05;
  // A hypothesis the images confirm must also pin its offset down: over
  // its correlating cells, the median of its NCC minus the better NCC of
  // its plane moved this fraction of the views' median distance to it
  // along the normal, either way, must exceed
  // hypothesis_min_offset_ncc_gain: the images must prefer its offset.
  // Far ahead, with little parallax, a plane some cm off correlates as
  // well as the surface, or better (0: no such test).
  double hypothesis_offset_depth_fraction = 0.01;
  // See hypothesis_offset_depth_fraction. A true plane of smooth texture
  // gains little over so small a move, so the bar is the sign
  // (docs/design-notes.md, "Planes").
  double hypothesis_min_offset_ncc_gain = 0.0;
  // Growth passes: each regrows every segment from its fitted polygon,
  // hidden by the others as the previous pass grew them (a wall below a
  // floor that had not grown yet).
  int passes = 2;

  void Check() const;
};

// Why growth took or left a cell (PlaneGrowthOptions::keep_cell_maps).
enum class CellVerdict : uint8_t {
  kTextured,           // the views correlate through the plane
  kPlain,              // untextured and equally bright in the views
  kInconsistent,       // textured, but the views do not correlate
  kPlainInconsistent,  // untextured, but brighter in some views than others
  kFewViews,           // fewer than min_views see it (grazing, hidden, outside)
  kLowParallax,        // its views' rays part by less than min_parallax_deg
  kAlongParallax,      // aperture test: its texture runs along the parallax
  kCarved,             // landmark rays pass through it: free space
  kClaimed,            // another plane's polygon covers it
};
constexpr int kNumCellVerdicts = 9;

// Every cell of a plane's growth grid with its verdict (PlaneGrowthOptions::
// keep_cell_maps; empty otherwise). Row r, column c is the cell whose
// in-plane corner is lo + cell_m * (c, r).
struct GrowthCellMap {
  cv::Mat1b verdict;  // CellVerdict
  cv::Mat1b fitted;   // 1: inside the fitted polygon (where growth starts)
  cv::Mat1b member;   // 1: in the grown polygon (before closing gaps)
  Eigen::Vector2d lo = Eigen::Vector2d::Zero();
};

// One segment's growth.
struct PlaneGrowthStats {
  int plane_id = 0;
  double cell_m = 0.0;  // cell side (m)
  double area_before_m2 = 0.0;
  double area_after_m2 = 0.0;
  int cells_textured = 0;  // added on texture evidence
  int cells_plain = 0;     // added as plain bridges
  int cells_carved = 0;    // free space by landmark rays (of the grid)
  int cells_hidden = 0;    // of the fitted polygon, hidden from every view
  GrowthCellMap cell_map;  // keep_cell_maps only
};

// One plane hypothesis' check against the images.
struct HypothesisStats {
  int inliers = 0;             // its landmarks
  int cells_textured = 0;      // over its hull, correlating across the views
  int cells_inconsistent = 0;  // ... judged but not correlating
  // Median NCC gain of its correlating cells over its plane moved along
  // the normal (hypothesis_offset_depth_fraction); 0 if not tested, -10
  // if no cell could be judged.
  double offset_ncc_gain = 0.0;
  bool confirmed = false;      // kept as a segment
  int plane_id = -1;           // its segment id if confirmed
  double area_m2 = 0.0;        // its polygon after growth if confirmed
};

struct PlaneGrowthReport {
  std::vector<PlaneGrowthStats> planes;  // the segments', then hypotheses'
  std::vector<HypothesisStats> hypotheses;
  int views = 0;  // frames used as views
  // Smallest and largest exposure gain of a view (1: none estimated).
  double min_exposure_gain = 1.0;
  double max_exposure_gain = 1.0;
  double seconds = 0.0;
};

// Loads the raw (distorted) grey image of a frame; called from several
// threads at once.
using GreyImageLoader = std::function<cv::Mat(int frame)>;

// Grows every segment's polygon over the cells its plane explains (see the
// top of this file), the largest segment first: a grown plane then hides
// what lies behind it from the next. Planes and inliers are unchanged.
// Then checks each of `hypotheses` (plane_hypotheses.h; ids following the
// segments'), most landmarks first: the cells over its landmarks' hull
// must correlate across the views (hypothesis_min_textured_*); a confirmed
// one grows from the confirmed cells like a segment and is appended to
// *segments, renumbered to follow them, its hull as landmark_polygon.
// Throws OptionsError for bad options and InputError for an image that is
// empty or not of the camera's size.
PlaneGrowthReport GrowPlanePolygons(
    const PlaneGrowthOptions& options, const Camera& camera,
    const std::vector<Rigid3d>& world_from_cam,
    const std::vector<Landmark>& landmarks, const std::vector<Track>& tracks,
    const GreyImageLoader& load_grey, std::vector<PlaneSegment>* segments,
    const std::vector<PlaneSegment>& hypotheses = {});

}  // namespace monomap
