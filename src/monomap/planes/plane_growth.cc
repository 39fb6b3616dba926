#include "monomap/planes/plane_growth.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <string>
#include <tuple>
#include <unordered_map>
#include <utility>

#include "monomap/camera/distorted_projector.h"
#include "monomap/geometry/polygon.h"
#include "monomap/planes/cell_outline.h"
#include "monomap/planes/plane_fitting.h"
#include "monomap/planes/ray_crossing.h"
#include "monomap/util/angles.h"
#include "monomap/util/error.h"
#include "monomap/util/image_sampling.h"
#include "monomap/util/progress.h"
#include "monomap/util/stats.h"

namespace monomap {

void PlaneGrowthOptions::Check() const {
  CheckOption(cell_px > 0 && std::isfinite(cell_px), "growth.cell_px",
              "must be positive");
  CheckOption(samples_per_side >= 2 && samples_per_side <= 16,
              "growth.samples_per_side", "must be in [2, 16]");
  CheckOption(max_growth_cells >= 0, "growth.max_growth_cells",
              "must be >= 0");
  CheckOption(max_views >= 2, "growth.max_views", "must be >= 2");
  CheckOption(min_views >= 2, "growth.min_views", "must be >= 2");
  CheckOption(min_parallax_deg >= 0 && min_parallax_deg < 90,
              "growth.min_parallax_deg", "must be in [0, 90)");
  CheckOption(min_plain_parallax_deg >= 0 && min_plain_parallax_deg < 90,
              "growth.min_plain_parallax_deg", "must be in [0, 90)");
  CheckOption(min_cos_view_angle >= 0 && min_cos_view_angle < 1,
              "growth.min_cos_view_angle", "must be in [0, 1)");
  CheckOption(min_texture_std >= 0, "growth.min_texture_std", "must be >= 0");
  CheckOption(min_ncc > -1 && min_ncc < 1, "growth.min_ncc",
              "must be in (-1, 1)");
  CheckOption(max_plain_brightness_diff >= 0,
              "growth.max_plain_brightness_diff", "must be >= 0");
  CheckOption(max_plain_run >= 0, "growth.max_plain_run", "must be >= 0");
  CheckOption(min_carving_landmarks >= 1, "growth.min_carving_landmarks",
              "must be >= 1");
  CheckOption(carve_margin_factor >= 0, "growth.carve_margin_factor",
              "must be >= 0");
  CheckOption(max_carving_rays >= 1, "growth.max_carving_rays",
              "must be >= 1");
  CheckOption(occluder_dilation_cells >= 0, "growth.occluder_dilation_cells",
              "must be >= 0");
  CheckOption(close_cells >= 0, "growth.close_cells", "must be >= 0");
  CheckOption(layer_cells >= 0, "growth.layer_cells", "must be >= 0");
  CheckOption(layer_max_angle_deg >= 0 && layer_max_angle_deg < 90,
              "growth.layer_max_angle_deg", "must be in [0, 90)");
  CheckOption(hypothesis_min_textured_cells >= 1,
              "growth.hypothesis_min_textured_cells", "must be >= 1");
  CheckOption(hypothesis_min_textured_fraction >= 0 &&
                  hypothesis_min_textured_fraction <= 1,
              "growth.hypothesis_min_textured_fraction", "must be in [0, 1]");
  CheckOption(hypothesis_offset_depth_fraction >= 0,
              "growth.hypothesis_offset_depth_fraction", "must be >= 0");
  CheckOption(hypothesis_min_offset_ncc_gain > -1 &&
                  hypothesis_min_offset_ncc_gain < 1,
              "growth.hypothesis_min_offset_ncc_gain", "must be in (-1, 1)");
  CheckOption(hypothesis_min_ncc_gain >= 0, "growth.hypothesis_min_ncc_gain",
              "must be >= 0");
  CheckOption(passes >= 1, "growth.passes", "must be >= 1");
  CheckOption(
      aperture_shift_samples > 0 && std::isfinite(aperture_shift_samples),
      "growth.aperture_shift_samples", "must be positive");
  CheckOption(aperture_max_ratio >= 0 && aperture_max_ratio <= 1,
              "growth.aperture_max_ratio", "must be in [0, 1]");
  CheckOption(min_occluder_cells >= 0, "growth.min_occluder_cells",
              "must be >= 0");
}

namespace {

// A frame used as a view: its grey image and pose.
struct View {
  int frame = 0;
  cv::Mat1b grey;
  Rigid3d cam_from_world;
  Eigen::Vector3d centre;
  double exposure_gain = 1.0;  // brightness relative to the other views
};

// Whether the ray from c to x meets another segment at least `clearance`
// (m) before x, inside its polygon widened by `dilation` (m).
bool Hidden(const std::vector<const PlaneSegment*>& occluders,
            const Eigen::Vector3d& c, const Eigen::Vector3d& x,
            double clearance, double dilation) {
  const Eigen::Vector3d d = x - c;
  const double dist = d.norm();
  const double lambda_max = 1.0 - clearance / std::max(dist, 1e-9);
  for (const PlaneSegment* o : occluders) {
    const Plane& pl = o->plane;
    const double denom = pl.normal.dot(d);
    if (std::abs(denom) < 1e-12) continue;
    const double lambda = -pl.SignedDistance(c) / denom;
    if (lambda <= 0.0 || lambda >= lambda_max) continue;
    const Eigen::Vector2d q = o->frame.ToPlane(c + lambda * d);
    if (DistanceToPolygon(o->polygon, q) <= dilation) return true;
  }
  return false;
}

// The grid of one segment: cell (r, c) covers plane coordinates
// lo + cell * (c, r) and one cell more.
struct Grid {
  Eigen::Vector2d lo = Eigen::Vector2d::Zero();
  double cell = 0.0;
  int rows = 0, cols = 0;
  Eigen::Vector2d Centre(int r, int c) const {
    return lo + cell * Eigen::Vector2d(c + 0.5, r + 0.5);
  }
};

enum class Evidence : uint8_t { kNone, kInconsistent, kTextured, kPlain };

// Photometric evidence of one cell: what the views see of it through the
// plane.
class CellJudge {
 public:
  CellJudge(const PlaneGrowthOptions& options, const PlaneSegment& segment,
            const Grid& grid, const std::vector<View>& views,
            const std::vector<const PlaneSegment*>& occluders,
            const DistortedProjector& projector)
      : o_(options),
        seg_(segment),
        grid_(grid),
        views_(views),
        occluders_(occluders),
        projector_(projector) {}

  // The cell's evidence; *ncc (if given) receives the median NCC of a
  // textured cell (-1 otherwise), *why (if given) the reason for kNone or
  // an untextured kInconsistent.
  Evidence Judge(int r, int c, double* ncc = nullptr,
                 CellVerdict* why = nullptr) const {
    if (ncc != nullptr) *ncc = -1.0;
    const int n = o_.samples_per_side * o_.samples_per_side;
    std::vector<float> patches;  // n values per seeing view
    std::vector<Eigen::Vector3d> rays;
    std::vector<const View*> seeing;
    std::vector<double> gains;
    const Eigen::Vector3d centre = seg_.frame.ToWorld(grid_.Centre(r, c));
    for (const View& v : views_) {
      const Eigen::Vector3d ray = centre - v.centre;
      const double dist = ray.norm();
      if (std::abs(seg_.plane.normal.dot(ray)) < o_.min_cos_view_angle * dist) {
        continue;
      }
      if (Hidden(occluders_, v.centre, centre, 0.5 * grid_.cell,
                 o_.occluder_dilation_cells * grid_.cell)) {
        continue;
      }
      if (!Sample(v, r, c, Eigen::Vector2d::Zero(), &patches)) continue;
      rays.push_back(ray / dist);
      seeing.push_back(&v);
      gains.push_back(v.exposure_gain);
    }
    const int nv = static_cast<int>(rays.size());
    CellVerdict unused;
    if (why == nullptr) why = &unused;
    const double parallax = MaxAngleDeg(rays);  // 0 for fewer than 2
    if (nv < o_.min_views ||
        parallax < std::min(o_.min_parallax_deg, o_.min_plain_parallax_deg)) {
      *why = nv < o_.min_views ? CellVerdict::kFewViews
                               : CellVerdict::kLowParallax;
      return Evidence::kNone;
    }
    const Evidence e = Photometric(patches, rays, gains, n, ncc, why);
    const double bar =
        e == Evidence::kPlain ? o_.min_plain_parallax_deg : o_.min_parallax_deg;
    if (parallax < bar) {
      if (ncc != nullptr) *ncc = -1.0;
      *why = CellVerdict::kLowParallax;
      return Evidence::kNone;
    }
    if (e == Evidence::kTextured && o_.aperture_test &&
        AlongParallaxOnly(r, c, seeing, rays, patches)) {
      if (ncc != nullptr) *ncc = -1.0;
      *why = CellVerdict::kAlongParallax;
      return Evidence::kNone;
    }
    return e;
  }

 private:
  // Appends view v's samples of cell (r, c), moved by `shift` (plane
  // coordinates, m); false (nothing appended) if one falls outside the
  // image.
  bool Sample(const View& v, int r, int c, const Eigen::Vector2d& shift,
              std::vector<float>* patch) const {
    const int k = o_.samples_per_side;
    const size_t start = patch->size();
    for (int i = 0; i < k * k; ++i) {
      const Eigen::Vector2d st =
          grid_.lo + shift +
          grid_.cell * Eigen::Vector2d(c + (i % k + 0.5) / k,
                                       r + (i / k + 0.5) / k);
      Eigen::Vector2d px;
      if (!projector_.Project(v.cam_from_world * seg_.frame.ToWorld(st),
                              &px) ||
          !projector_.camera().InImage(px, 1.0)) {
        patch->resize(start);
        return false;
      }
      patch->push_back(SampleGreyBilinear(
          v.grey, static_cast<float>(px.x()), static_cast<float>(px.y())));
    }
    return true;
  }

  // The aperture problem: a surface off the plane misregisters the views
  // along one direction of the plane only (where the rays of the two views
  // of most parallax through a point off it meet the plane). A texture
  // that hardly changes along it (an edge along the direction of travel: a
  // skirting board, a wall's foot seen along a corridor) correlates across
  // the views whatever the plane, so its NCC proves nothing. True when, in
  // most views, the patch moved along that direction decorrelates less than
  // aperture_max_ratio times as much as moved across it (1 - NCC grows
  // with the texture's gradient energy in the direction moved).
  bool AlongParallaxOnly(int r, int c, const std::vector<const View*>& seeing,
                         const std::vector<Eigen::Vector3d>& rays,
                         const std::vector<float>& patches) const {
    size_t a = 0, b = 1;
    MaxAngleDeg(rays, &a, &b);
    // A point a cell off the plane, seen from views a and b, meets the
    // plane at two places: their difference is the misregistration.
    const Eigen::Vector3d off = seg_.frame.ToWorld(grid_.Centre(r, c)) +
                                grid_.cell * seg_.plane.normal;
    const Eigen::Vector2d d = OnPlane(seeing[a]->centre, off) -
                              OnPlane(seeing[b]->centre, off);
    if (d.norm() < 1e-12) return true;
    const int n = o_.samples_per_side * o_.samples_per_side;
    const Eigen::Vector2d along = o_.aperture_shift_samples * grid_.cell /
                                  o_.samples_per_side * d.normalized();
    const Eigen::Vector2d across(-along.y(), along.x());
    std::vector<double> ratio;
    for (size_t v = 0; v < seeing.size(); ++v) {
      std::vector<float> moved_along, moved_across;
      if (!Sample(*seeing[v], r, c, along, &moved_along) ||
          !Sample(*seeing[v], r, c, across, &moved_across)) {
        continue;
      }
      const float* p = patches.data() + v * n;
      const double change_along = 1.0 - Ncc(p, moved_along.data(), n);
      const double change_across = 1.0 - Ncc(p, moved_across.data(), n);
      ratio.push_back(change_along / std::max(change_across, 1e-6));
    }
    return !ratio.empty() && Median(ratio) < o_.aperture_max_ratio;
  }

  // Where the ray from c through x meets the plane (plane coordinates).
  Eigen::Vector2d OnPlane(const Eigen::Vector3d& c,
                          const Eigen::Vector3d& x) const {
    const double sc = seg_.plane.SignedDistance(c);
    const double sx = seg_.plane.SignedDistance(x);
    return seg_.frame.ToPlane(c + sc / (sc - sx) * (x - c));
  }

  // Zero-mean normalized cross-correlation of two n-sample patches (0 if
  // either is flat).
  static double Ncc(const float* p, const float* q, int n) {
    double mp = 0, mq = 0;
    for (int i = 0; i < n; ++i) {
      mp += p[i];
      mq += q[i];
    }
    mp /= n;
    mq /= n;
    double cov = 0, vp = 0, vq = 0;
    for (int i = 0; i < n; ++i) {
      cov += (p[i] - mp) * (q[i] - mq);
      vp += (p[i] - mp) * (p[i] - mp);
      vq += (q[i] - mq) * (q[i] - mq);
    }
    return vp > 0 && vq > 0 ? cov / std::sqrt(vp * vq) : 0.0;
  }

  // The angle (deg) between the two rays that part most; *a, *b (if
  // given) receive their indices.
  static double MaxAngleDeg(const std::vector<Eigen::Vector3d>& rays,
                            size_t* a = nullptr, size_t* b = nullptr) {
    double min_cos = 1.0;
    for (size_t i = 0; i < rays.size(); ++i) {
      for (size_t j = i + 1; j < rays.size(); ++j) {
        if (rays[i].dot(rays[j]) >= min_cos) continue;
        min_cos = rays[i].dot(rays[j]);
        if (a != nullptr) *a = i;
        if (b != nullptr) *b = j;
      }
    }
    return RadToDeg(std::acos(std::clamp(min_cos, -1.0, 1.0)));
  }

  // Textured: NCC of each view's patch with the patch of the view whose
  // ray differs most from its own (the most parallax: a surface off the
  // plane shifts most there). Plain: the views' mean brightness, over
  // their exposure gains, against their median.
  Evidence Photometric(const std::vector<float>& patches,
                       const std::vector<Eigen::Vector3d>& rays,
                       const std::vector<double>& gains, int n,
                       double* median_ncc, CellVerdict* why) const {
    const int nv = static_cast<int>(rays.size());
    std::vector<double> means(nv), stds(nv);
    for (int v = 0; v < nv; ++v) {
      const float* p = patches.data() + static_cast<size_t>(v) * n;
      const double mean = std::accumulate(p, p + n, 0.0) / n;
      double var = 0.0;
      for (int i = 0; i < n; ++i) var += (p[i] - mean) * (p[i] - mean);
      means[v] = mean / gains[v];
      stds[v] = std::sqrt(var / n);
    }
    if (Median(stds) < o_.min_texture_std) {
      const double m = Median(means);
      const double band = o_.max_plain_brightness_diff * std::max(m, 10.0);
      for (double mean : means) {
        if (std::abs(mean - m) > band) {
          *why = CellVerdict::kPlainInconsistent;
          return Evidence::kInconsistent;
        }
      }
      return Evidence::kPlain;
    }
    std::vector<double> ncc(nv);
    for (int v = 0; v < nv; ++v) {
      int w = v;
      for (int u = 0; u < nv; ++u) {
        if (rays[u].dot(rays[v]) < rays[w].dot(rays[v])) w = u;
      }
      ncc[v] = Ncc(patches.data() + static_cast<size_t>(v) * n,
                   patches.data() + static_cast<size_t>(w) * n, n);
    }
    const double m = Median(ncc);
    if (median_ncc != nullptr) *median_ncc = m;
    return m >= o_.min_ncc ? Evidence::kTextured : Evidence::kInconsistent;
  }

  const PlaneGrowthOptions& o_;
  const PlaneSegment& seg_;
  const Grid& grid_;
  const std::vector<View>& views_;
  const std::vector<const PlaneSegment*>& occluders_;
  const DistortedProjector& projector_;
};

// Pixels per metre of the plane at plane point st, median over the views
// that see it in front: focal length / distance, foreshortened by
// sqrt(|cos|) (the geometric mean of the two in-plane directions). 0 if
// no view sees it.
double MedianResolution(const PlaneSegment& seg, const Eigen::Vector2d& st,
                        const std::vector<View>& views,
                        const DistortedProjector& projector) {
  const Eigen::Vector3d x = seg.frame.ToWorld(st);
  std::vector<double> ppm;
  for (const View& v : views) {
    Eigen::Vector2d px;
    if (!projector.Project(v.cam_from_world * x, &px) ||
        !projector.camera().InImage(px)) {
      continue;
    }
    const Eigen::Vector3d ray = x - v.centre;
    const double dist = ray.norm();
    const double cos = std::abs(seg.plane.normal.dot(ray)) / dist;
    ppm.push_back(projector.camera().fx / dist * std::sqrt(cos));
  }
  return ppm.empty() ? 0.0 : Median(ppm);
}

// Per cell: how many landmarks behind the plane were seen through it (the
// ray from an observing camera to the landmark crosses the plane there).
cv::Mat1i CarvingCounts(const PlaneGrowthOptions& o, const PlaneSegment& seg,
                        const Grid& grid,
                        const std::vector<Rigid3d>& world_from_cam,
                        const std::vector<Landmark>& landmarks,
                        const std::unordered_map<FeatureId, const Track*>& tracks) {
  cv::Mat1i counts = cv::Mat1i::zeros(grid.rows, grid.cols);
  cv::Mat1i last = cv::Mat1i(grid.rows, grid.cols, -1);
  const Eigen::Vector3d& n = seg.plane.normal;
  for (int li = 0; li < static_cast<int>(landmarks.size()); ++li) {
    const Landmark& l = landmarks[li];
    const auto it = tracks.find(l.id);
    if (it == tracks.end() || !l.x_in_world.allFinite()) continue;
    const double band =
        std::max(o.carve_margin_factor * grid.cell, CovarianceBand(l, n, 3.0));
    const double s_l = seg.plane.SignedDistance(l.x_in_world);
    if (std::abs(s_l) <= band) continue;
    ForEachCrossingRay(
        seg.plane, l.x_in_world, s_l, *it->second, world_from_cam,
        o.max_carving_rays, [&](const Eigen::Vector3d& hit) {
          const Eigen::Vector2d q =
              (seg.frame.ToPlane(hit) - grid.lo) / grid.cell;
          const int col = static_cast<int>(std::floor(q.x()));
          const int row = static_cast<int>(std::floor(q.y()));
          if (row < 0 || col < 0 || row >= grid.rows || col >= grid.cols) {
            return false;
          }
          if (last(row, col) == li) return false;  // count landmarks, not rays
          last(row, col) = li;
          ++counts(row, col);
          return false;
        });
  }
  return counts;
}

// The grid over the polygon's bounds plus the growth reach, and the cells
// whose centres lie inside the polygon. False if it would be too big.
bool MakeGrid(const PlaneSegment& seg, double cell, int reach, Grid* grid,
              cv::Mat1b* inside) {
  Eigen::Vector2d lo, hi;
  PolygonBounds(seg.polygon, &lo, &hi);
  grid->cell = cell;
  grid->lo = lo - (reach + 1) * cell * Eigen::Vector2d::Ones();
  const Eigen::Vector2d size = (hi - grid->lo) / cell;
  const double cols = std::ceil(size.x()) + reach + 1;
  const double rows = std::ceil(size.y()) + reach + 1;
  if (cols * rows > 4e6) return false;
  grid->cols = static_cast<int>(cols);
  grid->rows = static_cast<int>(rows);
  *inside = cv::Mat1b::zeros(grid->rows, grid->cols);
  for (int r = 0; r < grid->rows; ++r) {
    for (int c = 0; c < grid->cols; ++c) {
      if (PointInPolygon(seg.polygon, grid->Centre(r, c))) (*inside)(r, c) = 1;
    }
  }
  return true;
}

// What growing a segment needs that does not change between passes: its
// grid over the fitted polygon, the cells inside it, the carved cells.
struct SegmentGrid {
  bool ok = false;  // false: no view sees the polygon, or the grid is too big
  Grid grid;
  cv::Mat1b inside;
  cv::Mat1i carved;
};

// Per cell, the index in `others` of the parallel plane whose polygon it
// lies over, within layer_cells of it (-1: none): that plane's, not this
// one's to grow into.
cv::Mat1i ClaimedByOthers(const PlaneGrowthOptions& o, const PlaneSegment& seg,
                          const Grid& grid,
                          const std::vector<const PlaneSegment*>& others) {
  cv::Mat1i owner(grid.rows, grid.cols, -1);
  const double cos_max = std::cos(DegToRad(o.layer_max_angle_deg));
  const double layer = o.layer_cells * grid.cell;
  for (size_t k = 0; k < others.size(); ++k) {
    const PlaneSegment* b = others[k];
    if (std::abs(b->plane.normal.dot(seg.plane.normal)) < cos_max) continue;
    for (int r = 0; r < grid.rows; ++r) {
      for (int c = 0; c < grid.cols; ++c) {
        const Eigen::Vector3d x = seg.frame.ToWorld(grid.Centre(r, c));
        if (owner(r, c) < 0 && std::abs(b->plane.SignedDistance(x)) <= layer &&
            PointInPolygon(b->polygon, b->frame.ToPlane(x))) {
          owner(r, c) = static_cast<int>(k);
        }
      }
    }
  }
  return owner;
}

// The segment's plane and frame moved `shift` (m) along its normal: the
// same grid cells, on a parallel plane.
PlaneSegment Shifted(const PlaneSegment& seg, double shift) {
  PlaneSegment moved;
  moved.plane = seg.plane;
  moved.frame = seg.frame;
  moved.frame.origin += shift * seg.plane.normal;
  moved.plane.offset -= shift;
  return moved;
}

// The segment's plane and frame moved along its normal onto `rival` (a
// parallel plane: ClaimedByOthers) at its polygon's centroid: the same
// cells, seen as lying on the rival.
PlaneSegment OntoRival(const PlaneSegment& seg, const PlaneSegment& rival) {
  const Eigen::Vector3d c = seg.frame.ToWorld(PolygonCentroid(seg.polygon));
  return Shifted(seg, -rival.plane.SignedDistance(c) /
                          rival.plane.normal.dot(seg.plane.normal));
}

// What a cell of a segment's grid shows: free space (carved) gives no
// evidence; a cell claimed by a parallel plane gives none for a fitted
// segment, while a plane hypothesis (whose few landmarks may be a door leaf
// recessed in its wall) must explain it clearly better than that plane
// does: its NCC above the rival's by hypothesis_min_ncc_gain.
class CellEvidence {
 public:
  CellEvidence(const PlaneGrowthOptions& o, const PlaneSegment& seg,
               const SegmentGrid& g,
               const std::vector<const PlaneSegment*>& occluders,
               const std::vector<View>& views,
               const DistortedProjector& projector, bool compete)
      : o_(o),
        g_(g),
        judge_(o, seg, g.grid, views, occluders, projector),
        owner_(ClaimedByOthers(o, seg, g.grid, occluders)) {
    if (!compete) return;
    // A judge for each occluder that claims cells, at its place along the
    // normal.
    rival_of_.assign(occluders.size(), -1);
    for (int r = 0; r < owner_.rows; ++r) {
      for (int c = 0; c < owner_.cols; ++c) {
        const int k = owner_(r, c);
        if (k >= 0 && rival_of_[k] < 0) {
          rival_of_[k] = static_cast<int>(rivals_.size());
          rivals_.push_back(OntoRival(seg, *occluders[k]));
        }
      }
    }
    rival_judges_.reserve(rivals_.size());  // rivals_ no longer moves
    for (const PlaneSegment& rival : rivals_) {
      rival_judges_.emplace_back(o, rival, g.grid, views, occluders, projector);
    }
  }

  // *why (if given): the reason for kNone or an untextured kInconsistent.
  Evidence operator()(int r, int c, CellVerdict* why = nullptr) const {
    CellVerdict unused;
    if (why == nullptr) why = &unused;
    *why = CellVerdict::kClaimed;
    if (g_.carved(r, c) >= o_.min_carving_landmarks) {
      *why = CellVerdict::kCarved;
      return Evidence::kNone;
    }
    const int owner = owner_(r, c);
    if (owner < 0) return judge_.Judge(r, c, nullptr, why);
    if (rival_judges_.empty()) return Evidence::kNone;
    double ncc = -1.0, rival_ncc = -1.0;
    const Evidence e = judge_.Judge(r, c, &ncc, why);
    if (e == Evidence::kPlain) {  // no plane wins
      *why = CellVerdict::kClaimed;
      return Evidence::kNone;
    }
    if (e != Evidence::kTextured) return e;
    rival_judges_[rival_of_[owner]].Judge(r, c, &rival_ncc);
    return ncc >= rival_ncc + o_.hypothesis_min_ncc_gain
               ? Evidence::kTextured
               : Evidence::kInconsistent;
  }

 private:
  const PlaneGrowthOptions& o_;
  const SegmentGrid& g_;
  const CellJudge judge_;
  const cv::Mat1i owner_;
  std::vector<int> rival_of_;  // per occluder: index in rivals_, or -1
  std::vector<PlaneSegment> rivals_;
  std::vector<CellJudge> rival_judges_;
};

// Breadth-first growth from the inside cells, a ring of neighbours at a
// time (judged in parallel). run(r, c): cells since the last texture
// evidence; plain cells join only while it stays within max_plain_run.
cv::Mat1b Grow(const PlaneGrowthOptions& o, const Grid& grid,
               const cv::Mat1b& inside, const CellEvidence& judge,
               PlaneGrowthStats* stats, cv::Mat1b* proof) {
  cv::Mat1b member = inside.clone();
  *proof = inside.clone();
  cv::Mat1i run(grid.rows, grid.cols, 0);
  cv::Mat1b tried = inside.clone();
  static const int kDr[4] = {-1, 1, 0, 0}, kDc[4] = {0, 0, -1, 1};
  std::vector<cv::Point> frontier;
  for (int r = 0; r < grid.rows; ++r) {
    for (int c = 0; c < grid.cols; ++c) {
      if (member(r, c)) frontier.emplace_back(c, r);
    }
  }
  for (int ring = 0; ring < o.max_growth_cells && !frontier.empty(); ++ring) {
    std::vector<cv::Point> candidates;
    for (const cv::Point& p : frontier) {
      for (int k = 0; k < 4; ++k) {
        const int r = p.y + kDr[k], c = p.x + kDc[k];
        if (r < 0 || c < 0 || r >= grid.rows || c >= grid.cols || tried(r, c)) continue;
        tried(r, c) = 1;
        candidates.emplace_back(c, r);
      }
    }
    std::vector<Evidence> evidence(candidates.size(), Evidence::kNone);
    tbb::parallel_for(size_t{0}, candidates.size(), [&](size_t i) {
      const cv::Point& p = candidates[i];
      evidence[i] = judge(p.y, p.x);
    });
    frontier.clear();
    for (size_t i = 0; i < candidates.size(); ++i) {
      const cv::Point& p = candidates[i];
      int best_run = o.max_plain_run + 1;  // through the member neighbours
      for (int k = 0; k < 4; ++k) {
        const int r = p.y + kDr[k], c = p.x + kDc[k];
        if (r >= 0 && c >= 0 && r < grid.rows && c < grid.cols && member(r, c)) {
          best_run = std::min(best_run, run(r, c));
        }
      }
      if (evidence[i] == Evidence::kTextured) {
        run(p.y, p.x) = 0;
        (*proof)(p.y, p.x) = 1;
        ++stats->cells_textured;
      } else if (evidence[i] == Evidence::kPlain && best_run < o.max_plain_run) {
        run(p.y, p.x) = best_run + 1;
        ++stats->cells_plain;
      } else {
        continue;
      }
      member(p.y, p.x) = 1;
      frontier.push_back(p);
    }
  }
  return member;
}

SegmentGrid PrepareGrid(const PlaneGrowthOptions& o, const PlaneSegment& seg,
                        const std::vector<View>& views,
                        const DistortedProjector& projector,
                        const std::vector<Rigid3d>& world_from_cam,
                        const std::vector<Landmark>& landmarks,
                        const std::unordered_map<FeatureId, const Track*>& tracks) {
  SegmentGrid g;
  if (seg.polygon.size() < 3) return g;
  const double ppm =
      MedianResolution(seg, PolygonCentroid(seg.polygon), views, projector);
  if (ppm <= 0 ||
      !MakeGrid(seg, o.cell_px / ppm, o.max_growth_cells, &g.grid, &g.inside)) {
    return g;
  }
  g.carved = CarvingCounts(o, seg, g.grid, world_from_cam, landmarks, tracks);
  g.ok = true;
  return g;
}

// Leaves out the plain members outside the convex hull of the proof cells
// (the fitted polygon's and the textured ones): plain paint agrees with
// any plane, so it may only fill between proofs, never extend past them.
void KeepPlainBetweenProofs(const cv::Mat1b& proof, cv::Mat1b* member,
                            PlaneGrowthStats* stats) {
  std::vector<cv::Point2f> centres;
  for (int r = 0; r < proof.rows; ++r) {
    for (int c = 0; c < proof.cols; ++c) {
      if (proof(r, c)) centres.emplace_back(c, r);
    }
  }
  std::vector<cv::Point2f> hull;
  if (!centres.empty()) cv::convexHull(centres, hull);
  for (int r = 0; r < member->rows; ++r) {
    for (int c = 0; c < member->cols; ++c) {
      if (!(*member)(r, c) || proof(r, c)) continue;
      // Half a cell of slack: a plain cell beside the hull's edge stays.
      const bool within = hull.size() >= 3 &&
          cv::pointPolygonTest(hull, cv::Point2f(c, r), true) >= -0.5;
      if (!within) {
        (*member)(r, c) = 0;
        --stats->cells_plain;
      }
    }
  }
}

// Leaves out the fitted polygon's cells that every view that has them in
// its image sees through one of `occluders` meeting this plane (at more
// than layer_max_angle_deg): floor behind a wall's foot, taken in by a
// point misplaced along its rays, that no image shows. Parallel planes are
// left to the layer rule: a desk under its keyboard stays desk. Returns
// the cells dropped.
int DropHiddenCells(const PlaneGrowthOptions& o, const PlaneSegment& seg,
                    const Grid& grid, const std::vector<View>& views,
                    const std::vector<const PlaneSegment*>& occluders,
                    const DistortedProjector& projector, cv::Mat1b* inside) {
  const double cos_max = std::cos(DegToRad(o.layer_max_angle_deg));
  std::vector<const PlaneSegment*> crossing;
  for (const PlaneSegment* b : occluders) {
    if (std::abs(b->plane.normal.dot(seg.plane.normal)) < cos_max) {
      crossing.push_back(b);
    }
  }
  if (crossing.empty()) return 0;
  std::vector<cv::Point> cells;
  for (int r = 0; r < inside->rows; ++r) {
    for (int c = 0; c < inside->cols; ++c) {
      if ((*inside)(r, c)) cells.emplace_back(c, r);
    }
  }
  std::vector<uint8_t> hidden(cells.size(), 0);
  tbb::parallel_for(size_t{0}, cells.size(), [&](size_t i) {
    const Eigen::Vector3d x =
        seg.frame.ToWorld(grid.Centre(cells[i].y, cells[i].x));
    bool in_image = false;
    for (const View& v : views) {
      Eigen::Vector2d px;
      if (!projector.Project(v.cam_from_world * x, &px) ||
          !projector.camera().InImage(px)) {
        continue;
      }
      in_image = true;
      // Not widened as for growth: only an occluder's own polygon takes
      // away area that points support.
      if (!Hidden(crossing, v.centre, x, 0.5 * grid.cell, 0.0)) return;
    }
    hidden[i] = in_image ? 1 : 0;
  });
  int dropped = 0;
  for (size_t i = 0; i < cells.size(); ++i) {
    if (hidden[i]) (*inside)(cells[i].y, cells[i].x) = 0;
    dropped += hidden[i];
  }
  return dropped;
}

// The cells over a hypothesis' landmarks that the images confirm: kept
// in *inside when textured or plain; textured ones counted in *h. False
// when too few textured cells correlate across the views, or too many do
// not: then it is no plane of the scene.
bool ConfirmInside(const PlaneGrowthOptions& o, const CellEvidence& judge,
                   cv::Mat1b* inside, cv::Mat1b* plain, HypothesisStats* h) {
  std::vector<cv::Point> cells;
  for (int r = 0; r < inside->rows; ++r) {
    for (int c = 0; c < inside->cols; ++c) {
      if ((*inside)(r, c)) cells.emplace_back(c, r);
    }
  }
  std::vector<Evidence> evidence(cells.size(), Evidence::kNone);
  tbb::parallel_for(size_t{0}, cells.size(), [&](size_t i) {
    evidence[i] = judge(cells[i].y, cells[i].x);
  });
  *plain = cv::Mat1b::zeros(inside->size());
  for (size_t i = 0; i < cells.size(); ++i) {
    const cv::Point& p = cells[i];
    h->cells_textured += evidence[i] == Evidence::kTextured;
    h->cells_inconsistent += evidence[i] == Evidence::kInconsistent;
    if (evidence[i] == Evidence::kPlain) (*plain)(p.y, p.x) = 1;
    if (evidence[i] != Evidence::kTextured && evidence[i] != Evidence::kPlain) {
      (*inside)(p.y, p.x) = 0;
    }
  }
  return h->cells_textured >= o.hypothesis_min_textured_cells &&
         h->cells_textured >= o.hypothesis_min_textured_fraction *
                                  (h->cells_textured + h->cells_inconsistent);
}

// Every cell's verdict (keep_cell_maps), judged again in parallel: the
// judge is deterministic, so a grown cell gets the verdict it joined on.
GrowthCellMap MapCells(const Grid& grid, const cv::Mat1b& fitted,
                       const cv::Mat1b& member, const CellEvidence& judge) {
  GrowthCellMap map;
  map.verdict.create(grid.rows, grid.cols);
  map.fitted = fitted.clone();
  map.member = member.clone();
  map.lo = grid.lo;
  tbb::parallel_for(0, grid.rows, [&](int r) {
    for (int c = 0; c < grid.cols; ++c) {
      CellVerdict why = CellVerdict::kFewViews;
      const Evidence e = judge(r, c, &why);
      CellVerdict v = why;
      if (e == Evidence::kTextured) v = CellVerdict::kTextured;
      if (e == Evidence::kPlain) v = CellVerdict::kPlain;
      if (e == Evidence::kInconsistent &&
          why != CellVerdict::kPlainInconsistent) {
        v = CellVerdict::kInconsistent;
      }
      map.verdict(r, c) = static_cast<uint8_t>(v);
    }
  });
  return map;
}

// The member cells (0/1) as 0/255, holes and notches up to close_cells
// closed.
cv::Mat1b ClosedCells(const PlaneGrowthOptions& o, const cv::Mat1b& member) {
  cv::Mat1b cells = member * 255;
  if (o.close_cells > 0) {
    const int k = 2 * o.close_cells + 1;
    cv::morphologyEx(cells, cells, cv::MORPH_CLOSE,
                     cv::getStructuringElement(cv::MORPH_RECT, {k, k}));
  }
  return cells;
}

// The outline of the member cells, closed.
Polygon2d GrownCellsOutline(const PlaneGrowthOptions& o, const Grid& grid,
                            const cv::Mat1b& member) {
  return OutlineOfCells(ClosedCells(o, member), grid.lo, grid.cell, 0);
}

// The fitted polygon as drawn, less the cells found hidden (kept: the
// fitted cells left) and its slivers beside them (cells whose centres it
// misses), plus the cells growth added and the gaps closed next to them.
// Redrawing the fitted polygon as whole cells would widen it by up to half
// a cell, and closing would join its spikes, where a misplaced point may
// have pulled it past the foot of a wall the map lacks.
Polygon2d FittedAndGrownOutline(const PlaneGrowthOptions& o,
                                const PlaneSegment& seg, const SegmentGrid& g,
                                const cv::Mat1b& kept,
                                const cv::Mat1b& member) {
  const cv::Mat1b box = cv::getStructuringElement(cv::MORPH_RECT, {3, 3});
  cv::Mat1b near_grown;
  cv::dilate(member & ~g.inside, near_grown, box);
  const cv::Mat1b closed = ClosedCells(o, member);
  const cv::Mat1b hidden = g.inside & ~kept;
  cv::Mat1b beside_hidden;
  cv::dilate(hidden, beside_hidden, box);
  return OutlineOfPolygonAndCells(
      seg.polygon, (closed & near_grown) & ~g.inside,
      hidden | (beside_hidden & ~g.inside), g.grid.lo, g.grid.cell,
      /*fine=*/3);
}

// Grows one segment (its fitted polygon) against the others (occluders).
// Returns the new polygon, or the fitted one if nothing grew. With
// `hypothesis`, the segment is a plane hypothesis: only the cells of its
// polygon that the images confirm start the growth, and an empty polygon
// is returned when they do not confirm it.
Polygon2d GrowSegment(const PlaneGrowthOptions& o, const PlaneSegment& seg,
                      const SegmentGrid& g,
                      const std::vector<const PlaneSegment*>& occluders,
                      const std::vector<View>& views,
                      const DistortedProjector& projector,
                      PlaneGrowthStats* stats,
                      HypothesisStats* hypothesis = nullptr,
                      const std::vector<const PlaneSegment*>& trusted = {}) {
  if (!g.ok) return hypothesis ? Polygon2d{} : seg.polygon;
  const Grid& grid = g.grid;
  stats->cell_m = grid.cell;
  stats->cells_carved = cv::countNonZero(g.carved >= o.min_carving_landmarks);
  const CellEvidence judge(o, seg, g, occluders, views, projector,
                           /*compete=*/hypothesis != nullptr);
  cv::Mat1b inside = g.inside.clone(), plain_inside;
  if (o.drop_hidden_cells) {
    stats->cells_hidden =
        DropHiddenCells(o, seg, grid, views, trusted, projector, &inside);
  }
  if (hypothesis != nullptr &&
      !ConfirmInside(o, judge, &inside, &plain_inside, hypothesis)) {
    return {};
  }
  if (hypothesis != nullptr) {
    stats->cells_textured += hypothesis->cells_textured;
    stats->cells_plain += cv::countNonZero(plain_inside);
  }
  cv::Mat1b proof;
  cv::Mat1b member =
      Grow(o, grid, inside, judge, stats, &proof);
  // A hypothesis' plain cells prove nothing either.
  if (hypothesis != nullptr) proof.setTo(0, plain_inside);
  if (o.plain_between_proofs) KeepPlainBetweenProofs(proof, &member, stats);
  if (o.keep_cell_maps) stats->cell_map = MapCells(grid, inside, member, judge);
  const bool grew =
      stats->cells_textured + stats->cells_plain + stats->cells_hidden > 0;
  if (!grew && hypothesis == nullptr) return seg.polygon;
  if (hypothesis != nullptr) {
    Polygon2d poly = GrownCellsOutline(o, grid, member);
    return poly.size() >= 3 ? poly : Polygon2d{};
  }
  Polygon2d poly = o.keep_fitted_outline
                       ? FittedAndGrownOutline(o, seg, g, inside, member)
                       : GrownCellsOutline(o, grid, member);
  return poly.size() >= 3 ? poly : seg.polygon;
}

std::vector<View> LoadViews(const PlaneGrowthOptions& o, const Camera& camera,
                            const std::vector<Rigid3d>& world_from_cam,
                            const GreyImageLoader& load_grey) {
  const int n = static_cast<int>(world_from_cam.size());
  const int step = std::max(1, (n + o.max_views - 1) / o.max_views);
  std::vector<int> frames;
  for (int f = 0; f < n; f += step) frames.push_back(f);
  std::vector<View> views(frames.size());
  tbb::parallel_for(size_t{0}, frames.size(), [&](size_t i) {
    const int f = frames[i];
    cv::Mat img = load_grey(f);
    if (img.empty() || img.cols != camera.width || img.rows != camera.height) {
      throw InputError("image of frame " + std::to_string(f) +
                       " is empty or not of the camera's size");
    }
    if (img.channels() == 3) cv::cvtColor(img, img, cv::COLOR_BGR2GRAY);
    if (img.depth() != CV_8U) {
      throw InputError("image of frame " + std::to_string(f) + " is not 8-bit");
    }
    views[i].frame = f;
    views[i].grey = img;
    views[i].cam_from_world = world_from_cam[f].Inverse();
    views[i].centre = world_from_cam[f].translation;
  });
  return views;
}

constexpr double kNoGain = -10.0;  // a cell OffsetNccGain could not judge

// Median distance (m) from the views to the centroid of a segment's
// polygon: the depth at which the views see it.
double MedianViewDistance(const PlaneSegment& seg,
                          const std::vector<View>& views) {
  const Eigen::Vector3d c = seg.frame.ToWorld(PolygonCentroid(seg.polygon));
  std::vector<double> distances;
  for (const View& v : views) distances.push_back((c - v.centre).norm());
  return Median(distances);
}

// How well the images pin a hypothesis' offset down: over the cells of its
// hull that correlate on its plane, the median of their NCC minus the
// better of their NCCs on the plane moved `shift` either way along the
// normal (cells that either moved plane cannot judge are skipped; kNoGain
// if none is left).
double OffsetNccGain(const PlaneGrowthOptions& o, const PlaneSegment& seg,
                     const SegmentGrid& g,
                     const std::vector<const PlaneSegment*>& occluders,
                     const std::vector<View>& views,
                     const DistortedProjector& projector, double shift) {
  const PlaneSegment nearer = Shifted(seg, -shift),
                     farther = Shifted(seg, shift);
  const CellJudge at(o, seg, g.grid, views, occluders, projector);
  const CellJudge at_nearer(o, nearer, g.grid, views, occluders, projector);
  const CellJudge at_farther(o, farther, g.grid, views, occluders, projector);
  std::vector<cv::Point> cells;
  for (int r = 0; r < g.inside.rows; ++r) {
    for (int c = 0; c < g.inside.cols; ++c) {
      if (g.inside(r, c)) cells.emplace_back(c, r);
    }
  }
  std::vector<double> gain(cells.size(), kNoGain);
  tbb::parallel_for(size_t{0}, cells.size(), [&](size_t i) {
    const cv::Point& p = cells[i];
    double ncc = -1.0, ncc_nearer = -1.0, ncc_farther = -1.0;
    if (at.Judge(p.y, p.x, &ncc) != Evidence::kTextured) return;
    at_nearer.Judge(p.y, p.x, &ncc_nearer);
    at_farther.Judge(p.y, p.x, &ncc_farther);
    if (ncc_nearer < -0.5 || ncc_farther < -0.5) return;  // not judged
    gain[i] = ncc - std::max(ncc_nearer, ncc_farther);
  });
  gain.erase(std::remove(gain.begin(), gain.end(), kNoGain), gain.end());
  return gain.empty() ? kNoGain : Median(gain);
}

// Checks the hypotheses against the images, most landmarks first (see
// GrowPlanePolygons); confirmed ones join *segments and hide what lies
// behind them from the next.
void ConfirmHypotheses(
    const PlaneGrowthOptions& o, const std::vector<View>& views,
    const DistortedProjector& projector,
    const std::vector<Rigid3d>& world_from_cam,
    const std::vector<Landmark>& landmarks,
    const std::unordered_map<FeatureId, const Track*>& track_by_id,
    const std::vector<PlaneSegment>& hypotheses,
    std::vector<PlaneSegment>* segments, PlaneGrowthReport* report) {
  std::vector<int> order(hypotheses.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return hypotheses[a].inlier_ids.size() > hypotheses[b].inlier_ids.size();
  });
  for (int i : order) {
    PlaneSegment seg = hypotheses[i];
    HypothesisStats h;
    h.inliers = static_cast<int>(seg.inlier_ids.size());
    const SegmentGrid g = PrepareGrid(o, seg, views, projector, world_from_cam,
                                      landmarks, track_by_id);
    std::vector<const PlaneSegment*> occluders;
    for (const PlaneSegment& other : *segments) {
      if (other.polygon.size() >= 3) occluders.push_back(&other);
    }
    PlaneGrowthStats stats;
    stats.area_before_m2 = std::abs(PolygonArea(seg.polygon));
    const Polygon2d grown =
        GrowSegment(o, seg, g, occluders, views, projector, &stats, &h);
    h.confirmed = grown.size() >= 3;
    if (h.confirmed && o.hypothesis_offset_depth_fraction > 0) {
      h.offset_ncc_gain = OffsetNccGain(
          o, seg, g, occluders, views, projector,
          o.hypothesis_offset_depth_fraction * MedianViewDistance(seg, views));
      h.confirmed = h.offset_ncc_gain > o.hypothesis_min_offset_ncc_gain;
    }
    if (h.confirmed) {
      seg.id = static_cast<int>(segments->size());
      seg.landmark_polygon = seg.polygon;
      seg.polygon = grown;
      h.plane_id = seg.id;
      h.area_m2 = std::abs(PolygonArea(grown));
      stats.plane_id = seg.id;
      stats.area_after_m2 = h.area_m2;
      report->planes.push_back(stats);
      segments->push_back(std::move(seg));
    }
    report->hypotheses.push_back(h);
  }
}

// Each view's exposure gain relative to the others, from the tracks: a
// feature's surroundings (a box mean around it) brighten and darken with
// the frames that see it, so a view's gain is the median over its features
// of their brightness there over their median across the views. Views
// with too few features keep 1. Returns the smallest and largest gain of
// a view.
std::pair<double, double> EstimateExposureGains(
    const std::vector<Track>& tracks, std::vector<View>* views) {
  constexpr int kHalfBox = 4;       // 9 x 9 px: robust to sub-pixel drift
  constexpr int kMinFeatures = 20;  // per view, for a gain
  constexpr double kMinBrightness = 10.0;  // darker: noise, not exposure
  std::unordered_map<int, size_t> view_of_frame;
  for (size_t v = 0; v < views->size(); ++v) {
    view_of_frame[(*views)[v].frame] = v;
  }
  std::vector<std::vector<double>> ratios(views->size());
  std::vector<std::pair<size_t, double>> seen;
  for (const Track& t : tracks) {
    seen.clear();
    for (const Observation& o : t.observations) {
      const auto it = view_of_frame.find(o.frame);
      if (it == view_of_frame.end()) continue;
      const cv::Mat1b& grey = (*views)[it->second].grey;
      const cv::Rect box(static_cast<int>(std::lround(o.px.x())) - kHalfBox,
                         static_cast<int>(std::lround(o.px.y())) - kHalfBox,
                         2 * kHalfBox + 1, 2 * kHalfBox + 1);
      if ((box & cv::Rect(0, 0, grey.cols, grey.rows)) != box) continue;
      seen.emplace_back(it->second, cv::mean(grey(box))[0]);
    }
    if (seen.size() < 2) continue;
    std::vector<double> values;
    for (const auto& s : seen) values.push_back(s.second);
    const double median = Median(values);
    if (median < kMinBrightness) continue;
    for (const auto& s : seen) ratios[s.first].push_back(s.second / median);
  }
  double lo = 1.0, hi = 1.0;  // every view's gain, estimated or kept at 1
  for (size_t v = 0; v < views->size(); ++v) {
    if (static_cast<int>(ratios[v].size()) >= kMinFeatures) {
      (*views)[v].exposure_gain = Median(std::move(ratios[v]));
    }
    lo = v == 0 ? (*views)[v].exposure_gain
                : std::min(lo, (*views)[v].exposure_gain);
    hi = v == 0 ? (*views)[v].exposure_gain
                : std::max(hi, (*views)[v].exposure_gain);
  }
  return {lo, hi};
}

}  // namespace

PlaneGrowthReport GrowPlanePolygons(
    const PlaneGrowthOptions& options, const Camera& camera,
    const std::vector<Rigid3d>& world_from_cam,
    const std::vector<Landmark>& landmarks, const std::vector<Track>& tracks,
    const GreyImageLoader& load_grey, std::vector<PlaneSegment>* segments,
    const std::vector<PlaneSegment>& hypotheses) {
  options.Check();
  Timer timer;
  PlaneGrowthReport report;
  if (!options.enabled || segments->empty() || world_from_cam.size() < 2) {
    return report;
  }
  std::vector<View> views =
      LoadViews(options, camera, world_from_cam, load_grey);
  report.views = static_cast<int>(views.size());
  if (options.compensate_exposure) {
    std::tie(report.min_exposure_gain, report.max_exposure_gain) =
        EstimateExposureGains(tracks, &views);
  }
  const DistortedProjector projector(camera);
  std::unordered_map<FeatureId, const Track*> track_by_id;
  for (const Track& t : tracks) track_by_id[t.id] = &t;
  // Largest first: its grown polygon then hides what lies behind it.
  std::vector<int> order(segments->size());
  std::iota(order.begin(), order.end(), 0);
  std::vector<double> areas(segments->size());
  for (size_t i = 0; i < segments->size(); ++i) {
    areas[i] = std::abs(PolygonArea((*segments)[i].polygon));
  }
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return areas[a] > areas[b]; });
  std::vector<Polygon2d> original(segments->size());
  // What the landmarks alone support: plane fitting's own landmark_polygon
  // if it extended the polygon over absorbed points, else the polygon.
  std::vector<Polygon2d> supported(segments->size());
  std::vector<SegmentGrid> grids(segments->size());
  for (size_t i = 0; i < segments->size(); ++i) {
    original[i] = (*segments)[i].polygon;
    supported[i] = (*segments)[i].landmark_polygon.empty()
                       ? original[i]
                       : (*segments)[i].landmark_polygon;
    grids[i] = PrepareGrid(options, (*segments)[i], views, projector,
                           world_from_cam, landmarks, track_by_id);
  }
  for (int pass = 0; pass < options.passes; ++pass) {
    report.planes.clear();
    for (int i : order) {
      PlaneSegment& seg = (*segments)[i];
      PlaneGrowthStats stats;
      stats.plane_id = seg.id;
      stats.area_before_m2 = areas[i];
      stats.area_after_m2 = areas[i];
      if (original[i].size() >= 3) {
        seg.polygon = original[i];  // regrown against the others' growth
        std::vector<const PlaneSegment*> occluders, trusted;
        for (size_t j = 0; j < segments->size(); ++j) {
          const PlaneSegment& other = (*segments)[j];
          if (&other == &seg || other.polygon.size() < 3) continue;
          occluders.push_back(&other);
          const double cell = grids[j].ok ? grids[j].grid.cell : 0.0;
          if (cell > 0 && std::abs(PolygonArea(other.polygon)) >=
                              options.min_occluder_cells * cell * cell) {
            trusted.push_back(&other);
          }
        }
        seg.polygon = GrowSegment(options, seg, grids[i], occluders, views,
                                  projector, &stats, nullptr, trusted);
        stats.area_after_m2 = std::abs(PolygonArea(seg.polygon));
      }
      report.planes.push_back(stats);
    }
  }
  // What the landmarks alone support, for localization (TexturedPlane).
  for (size_t i = 0; i < segments->size(); ++i) {
    PlaneSegment& seg = (*segments)[i];
    seg.landmark_polygon.clear();
    if (seg.polygon != supported[i]) seg.landmark_polygon = supported[i];
  }
  ConfirmHypotheses(options, views, projector, world_from_cam, landmarks,
                    track_by_id, hypotheses, segments, &report);
  report.seconds = timer.ElapsedSeconds();
  return report;
}

}  // namespace monomap
