#include "monomap/rendering/renderer.h"

#include <tbb/parallel_for.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <string>

#include "monomap/geometry/polygon.h"
#include "monomap/util/error.h"

namespace monomap {
namespace {

// Pixels per span sharing one mip level: the footprint changes slowly along
// a row, and one log2 per span keeps the per-pixel work to adds and a
// division.
constexpr int kSpan = 16;

// Renders of at least this many pixels split their rows over threads
// (a 752x480 render of the desk map took 4 ms alone).
constexpr int64_t kParallelPixels = 200 * 150;

// One mip level, C floats per texel (premultiplied channels then alpha),
// padded by one texel of zeros on every side so that bilinear sampling at
// the border needs no clamping and fades alpha to 0 outside the texture.
struct Level {
  int width = 0;   // texels, without padding
  int height = 0;
  int stride = 0;  // floats per padded row
  std::vector<float> data;

  float* Row(int r) { return data.data() + (r + 1) * stride; }
};

template <int C>
std::vector<Level> BuildPyramid(const cv::Mat& bgra, const cv::Mat& mask,
                                bool mipmaps) {
  std::vector<Level> levels(1);
  Level& base = levels[0];
  base.width = bgra.cols;
  base.height = bgra.rows;
  base.stride = (base.width + 2) * C;
  base.data.assign(static_cast<size_t>(base.stride) * (base.height + 2), 0.f);
  for (int r = 0; r < bgra.rows; ++r) {
    const uint8_t* src = bgra.ptr<uint8_t>(r);
    const uint8_t* m = mask.ptr<uint8_t>(r);
    float* dst = base.Row(r) + C;
    for (int c = 0; c < bgra.cols; ++c, src += 4, dst += C) {
      const float a = m[c] ? src[3] * (1.f / 255.f) : 0.f;
      if constexpr (C == 2) {
        // Same weights as cv::COLOR_BGR2GRAY.
        dst[0] = a * (0.114f * src[0] + 0.587f * src[1] + 0.299f * src[2]);
      } else {
        dst[0] = a * src[0];
        dst[1] = a * src[1];
        dst[2] = a * src[2];
      }
      dst[C - 1] = a;
    }
  }
  if (!mipmaps) return levels;
  while (levels.back().width > 1 || levels.back().height > 1) {
    const Level& prev = levels.back();
    Level next;
    next.width = (prev.width + 1) / 2;
    next.height = (prev.height + 1) / 2;
    next.stride = (next.width + 2) * C;
    next.data.assign(static_cast<size_t>(next.stride) * (next.height + 2), 0.f);
    // 2x2 box on premultiplied values; texels beyond an odd border are the
    // zero padding, i.e. unseen, so they lower alpha instead of the colour.
    for (int r = 0; r < next.height; ++r) {
      const float* a = prev.data.data() + (2 * r + 1) * prev.stride + C;
      const float* b = a + prev.stride;
      float* dst = next.Row(r) + C;
      for (int c = 0; c < next.width; ++c, a += 2 * C, b += 2 * C, dst += C) {
        for (int k = 0; k < C; ++k) {
          dst[k] = 0.25f * (a[k] + a[C + k] + b[k] + b[C + k]);
        }
      }
    }
    levels.push_back(std::move(next));
  }
  return levels;
}

// Clips a convex polygon (camera frame) to z >= z_near (Sutherland-Hodgman).
int ClipNear(const std::array<Eigen::Vector3d, 4>& in, double z_near,
             std::array<Eigen::Vector3d, 8>* out) {
  int n = 0;
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector3d& a = in[i];
    const Eigen::Vector3d& b = in[(i + 1) % 4];
    const bool a_in = a.z() >= z_near;
    const bool b_in = b.z() >= z_near;
    if (a_in) (*out)[n++] = a;
    if (a_in != b_in) {
      const double s = (z_near - a.z()) / (b.z() - a.z());
      (*out)[n++] = a + s * (b - a);
    }
  }
  return n;
}

}  // namespace

void RendererOptions::Check() const {
  CheckOption(std::isfinite(mip_bias) && std::abs(mip_bias) <= 8,
              "rendering.mip_bias", "must be finite, within [-8, 8]");
  CheckOption(background_grey >= 0 && background_grey <= 255,
              "rendering.background_grey", "must be in [0, 255]");
  CheckOption(alpha_threshold > 0 && alpha_threshold <= 1,
              "rendering.alpha_threshold", "must be in (0, 1]");
  CheckOption(std::isfinite(z_near_m) && z_near_m > 0, "rendering.z_near_m",
              "must be positive");
}

struct Renderer::PlaneData {
  PlaneFrame frame;
  double pixels_per_meter = 0;
  // Region worth scanning, in (s, t) metres: the texture rectangle (and the
  // polygon's bounds), widened by one texel for the bilinear support.
  Eigen::Vector2d st_min, st_max;
  std::vector<Level> grey;   // C = 2
  std::vector<Level> color;  // C = 4, empty unless options.enable_color

  template <int C>
  const std::vector<Level>& levels() const {
    if constexpr (C == 2) {
      return grey;
    } else {
      return color;
    }
  }
};

Renderer::Renderer(const Map& map, const RendererOptions& options)
    : Renderer(map.planes, options) {}

Renderer::~Renderer() = default;
Renderer::Renderer(Renderer&&) noexcept = default;
Renderer& Renderer::operator=(Renderer&&) noexcept = default;

Renderer::Renderer(const std::vector<TexturedPlane>& planes,
                   const RendererOptions& options)
    : options_(options) {
  options_.Check();
  for (const TexturedPlane& plane : planes) {
    if (plane.texture.empty()) continue;
    const std::string name = "plane " + std::to_string(plane.id);
    if (plane.texture.depth() != CV_8U) {
      throw InputError(name + ": texture must be 8-bit");
    }
    if (!(std::isfinite(plane.pixels_per_meter) &&
          plane.pixels_per_meter > 0)) {
      throw InputError(name + ": pixels_per_meter must be positive");
    }
    cv::Mat bgra;
    switch (plane.texture.channels()) {
      case 4: bgra = plane.texture; break;
      case 3: cv::cvtColor(plane.texture, bgra, cv::COLOR_BGR2BGRA); break;
      case 1: cv::cvtColor(plane.texture, bgra, cv::COLOR_GRAY2BGRA); break;
      default:
        throw InputError(name + ": texture must have 1, 3 or 4 channels");
    }
    auto data = std::make_shared<PlaneData>();
    data->frame = plane.frame;
    data->pixels_per_meter = plane.pixels_per_meter;
    const double ppm = plane.pixels_per_meter;
    Eigen::Vector2d lo(0, 0);
    Eigen::Vector2d hi(bgra.cols / ppm, bgra.rows / ppm);

    cv::Mat mask(bgra.size(), CV_8U, cv::Scalar(255));
    const Polygon2d& polygon = options_.clip_to_landmark_polygon &&
                                       plane.landmark_polygon.size() >= 3
                                   ? plane.landmark_polygon
                                   : plane.polygon;
    if (options_.clip_to_polygon && polygon.size() >= 3) {
      // fillPoly marks the texels whose centres are inside; vertices in
      // texel coordinates with 8 fractional bits.
      constexpr int kShift = 8;
      std::vector<cv::Point> pts;
      for (const Eigen::Vector2d& st : polygon) {
        const Eigen::Vector2d px = st * ppm - Eigen::Vector2d(0.5, 0.5);
        pts.emplace_back(static_cast<int>(std::lround(px.x() * (1 << kShift))),
                         static_cast<int>(std::lround(px.y() * (1 << kShift))));
      }
      mask.setTo(0);
      cv::fillPoly(mask, std::vector<std::vector<cv::Point>>{pts},
                   cv::Scalar(255), cv::LINE_8, kShift);
      Eigen::Vector2d pmin, pmax;
      PolygonBounds(polygon, &pmin, &pmax);
      lo = lo.cwiseMax(pmin);
      hi = hi.cwiseMin(pmax);
      if (lo.x() > hi.x() || lo.y() > hi.y()) continue;  // nothing inside
    }
    data->st_min = lo - Eigen::Vector2d::Constant(1.0 / ppm);
    data->st_max = hi + Eigen::Vector2d::Constant(1.0 / ppm);
    data->grey = BuildPyramid<2>(bgra, mask, options_.use_mipmaps);
    if (options_.enable_color) {
      data->color = BuildPyramid<4>(bgra, mask, options_.use_mipmaps);
    }
    planes_.push_back(std::move(data));
  }
}

int Renderer::num_planes() const { return static_cast<int>(planes_.size()); }

Renderer Renderer::WithMipBias(double mip_bias) const {
  Renderer r;
  r.options_ = options_;
  r.options_.mip_bias = mip_bias;
  r.options_.Check();
  r.planes_ = planes_;
  return r;
}

size_t Renderer::MemoryBytes() const {
  size_t bytes = 0;
  for (const auto& p : planes_) {
    for (const Level& l : p->grey) bytes += l.data.size() * sizeof(float);
    for (const Level& l : p->color) bytes += l.data.size() * sizeof(float);
  }
  return bytes;
}

RenderStats Renderer::Render(const Camera& camera,
                             const Rigid3d& world_from_cam, cv::Mat* grey,
                             cv::Mat* depth) const {
  if (grey == nullptr) throw OptionsError("Render: grey must not be null");
  return RenderImpl<2>(camera, world_from_cam, grey, depth);
}

RenderStats Renderer::RenderColor(const Camera& camera,
                                  const Rigid3d& world_from_cam, cv::Mat* bgr,
                                  cv::Mat* depth) const {
  if (bgr == nullptr) throw OptionsError("RenderColor: bgr must not be null");
  CheckOption(options_.enable_color, "rendering.enable_color",
              "must be true to call RenderColor");
  return RenderImpl<4>(camera, world_from_cam, bgr, depth);
}

std::vector<RenderStats> Renderer::RenderBatch(
    const Camera& camera, const std::vector<Rigid3d>& poses,
    std::vector<cv::Mat>* greys, std::vector<cv::Mat>* depths) const {
  if (greys == nullptr) throw OptionsError("RenderBatch: greys must not be null");
  const int n = static_cast<int>(poses.size());
  greys->resize(n);
  if (depths != nullptr) depths->resize(n);
  std::vector<RenderStats> stats(n);
  // Small grain: one render at 80x60 takes ~0.1 ms, enough to amortize the
  // scheduling.
  tbb::parallel_for(tbb::blocked_range<int>(0, n, 8),
                    [&](const tbb::blocked_range<int>& range) {
                      for (int i = range.begin(); i < range.end(); ++i) {
                        stats[i] = RenderImpl<2>(
                            camera, poses[i], &(*greys)[i],
                            depths != nullptr ? &(*depths)[i] : nullptr);
                      }
                    });
  return stats;
}

namespace {

// A plane as one camera sees it.
struct PlaneProjection {
  Eigen::Matrix3d texel_from_pixel;
  std::array<Eigen::Vector2d, 8> poly;  // image polygon of the scanned region
  int n = 0;                            // vertices of poly
  int row0 = 0, row1 = 0;               // rows it may cover
};

// The scanned region's corners (camera frame), clipped to the near plane
// and projected: a convex polygon, whose extent per row bounds the pixels
// to visit. False if nothing of it is in the image.
bool ProjectScanRegion(const std::array<Eigen::Vector3d, 4>& corners,
                       const Camera& camera, double z_near,
                       PlaneProjection* proj) {
  std::array<Eigen::Vector3d, 8> clipped;
  const int n = ClipNear(corners, z_near, &clipped);
  if (n < 3) return false;
  std::array<Eigen::Vector2d, 8>& poly = proj->poly;
  double vmin = std::numeric_limits<double>::infinity();
  double vmax = -vmin, umin_all = vmin, umax_all = -vmin;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d& x = clipped[i];
    poly[i] = {camera.fx * x.x() / x.z() + camera.cx,
               camera.fy * x.y() / x.z() + camera.cy};
    vmin = std::min(vmin, poly[i].y());
    vmax = std::max(vmax, poly[i].y());
    umin_all = std::min(umin_all, poly[i].x());
    umax_all = std::max(umax_all, poly[i].x());
  }
  const int height = camera.height;
  if (vmax < -1 || vmin > height || umax_all < -1 || umin_all > camera.width) {
    return false;
  }
  proj->n = n;
  proj->row0 = std::max(0, static_cast<int>(std::floor(vmin - 1)));
  proj->row1 = std::min(height - 1, static_cast<int>(std::ceil(vmax + 1)));
  return true;
}

// Projects the plane region [st_min, st_max] (metres in the plane frame)
// with cam_from_world = [rot | trans]. False if the plane faces away (or
// is seen edge-on) or the region is out of view.
bool ProjectPlane(const PlaneFrame& frame, double ppm,
                  const Eigen::Vector2d& st_min, const Eigen::Vector2d& st_max,
                  const Eigen::Matrix3d& rot, const Eigen::Vector3d& trans,
                  const Camera& camera, const Eigen::Matrix3d& k,
                  const RendererOptions& options, PlaneProjection* proj) {
  const Eigen::Vector3d u_c = rot * frame.u_axis;
  const Eigen::Vector3d v_c = rot * frame.v_axis;
  const Eigen::Vector3d o_c = rot * frame.origin + trans;
  // Camera centre on the normal's side <=> n . (0 - o) > 0.
  const double side = -u_c.cross(v_c).dot(o_c);
  if (options.cull_back_faces ? side <= 1e-12 : std::abs(side) <= 1e-12) {
    return false;
  }
  // pixel_from_texel = K [R u, R v, R o + t] with texel centres at
  // (c + 0.5) / ppm. Its inverse maps pixels to homogeneous texels whose
  // third coordinate is exactly 1/z.
  Eigen::Matrix3d m;
  m.col(0) = u_c / ppm;
  m.col(1) = v_c / ppm;
  m.col(2) = o_c + 0.5 * (u_c + v_c) / ppm;
  proj->texel_from_pixel = (k * m).inverse();
  if (!proj->texel_from_pixel.allFinite()) return false;
  const std::array<Eigen::Vector3d, 4> corners = {
      o_c + st_min.x() * u_c + st_min.y() * v_c,
      o_c + st_max.x() * u_c + st_min.y() * v_c,
      o_c + st_max.x() * u_c + st_max.y() * v_c,
      o_c + st_min.x() * u_c + st_max.y() * v_c};
  return ProjectScanRegion(corners, camera, options.z_near_m, proj);
}

// Extent [lo, hi] of the polygon within the band of rows [v - 1, v + 1];
// lo > hi if the band misses it.
void PolygonRowExtent(const std::array<Eigen::Vector2d, 8>& poly, int n, int v,
                      double* lo_out, double* hi_out) {
  const double b0 = v - 1.0, b1 = v + 1.0;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector2d& p = poly[i];
    const Eigen::Vector2d& q = poly[(i + 1) % n];
    if (p.y() >= b0 && p.y() <= b1) {
      lo = std::min(lo, p.x());
      hi = std::max(hi, p.x());
    }
    for (double b : {b0, b1}) {
      if ((p.y() - b) * (q.y() - b) < 0) {
        const double x =
            p.x() + (b - p.y()) / (q.y() - p.y()) * (q.x() - p.x());
        lo = std::min(lo, x);
        hi = std::max(hi, x);
      }
    }
  }
  *lo_out = lo;
  *hi_out = hi;
}

// Mip level of the span [s0, s1] of row v from the texel footprint at its
// centre: rho^2 = |det d texel / d pixel| (area) or the squared longest of
// its columns; level = round(log2 rho + bias), within the pyramid.
int MipLevel(const Eigen::Matrix3d& texel_from_pixel, int s0, int s1, int v,
             int num_levels, bool area_footprint, double bias) {
  if (num_levels <= 1) return 0;
  const double uc = 0.5 * (s0 + s1);
  const Eigen::Vector3d t = texel_from_pixel * Eigen::Vector3d(uc, v, 1);
  if (!(t.z() > 0)) return 0;
  const double x = t.x() / t.z(), y = t.y() / t.z();
  const Eigen::Matrix3d& hd = texel_from_pixel;
  const double dxdu = (hd(0, 0) - x * hd(2, 0)) / t.z();
  const double dydu = (hd(1, 0) - y * hd(2, 0)) / t.z();
  const double dxdv = (hd(0, 1) - x * hd(2, 1)) / t.z();
  const double dydv = (hd(1, 1) - y * hd(2, 1)) / t.z();
  const double rho2 = area_footprint ? std::abs(dxdu * dydv - dydu * dxdv)
                                     : std::max(dxdu * dxdu + dydu * dydu,
                                                dxdv * dxdv + dydv * dydv);
  const double lambda = 0.5 * std::log2(rho2) + bias;
  if (!(lambda > 0.5)) return 0;
  return std::min(num_levels - 1, static_cast<int>(std::floor(lambda + 0.5)));
}

// What every drawn pixel shares: the buffers and the options.
struct Raster {
  int width = 0;
  float* zbuf = nullptr;  // inverse depths, 0 = background
  cv::Mat* image = nullptr;
  float inv_near = 0;
  float alpha_min = 0;
  double mip_bias = 0;
  bool area_footprint = false;
};

// One image row: the homography's terms that depend on the row only, and
// the row's buffers.
struct RowTarget {
  float x_row, y_row, w_row;
  float* zrow;
  uint8_t* out;
};

// Draws the pixels [s0, s1] of a row from mip level `level`, bilinearly,
// where the plane is the nearest surface so far. True if any was drawn.
template <int C>
bool DrawSpan(const Level& lev, int level, const Eigen::Matrix3f& h,
              const RowTarget& row, int s0, int s1, const Raster& raster) {
  constexpr int kOut = C == 2 ? 1 : 3;
  // Level-0 texel x -> padded level-L coordinate (x + 0.5) / 2^L - 0.5 + 1.
  const float scale = std::ldexp(1.f, -level);
  const float offset = 0.5f * scale + 0.5f;
  const float x_max = static_cast<float>(lev.width + 1);
  const float y_max = static_cast<float>(lev.height + 1);
  const float* texels = lev.data.data();
  const int stride = lev.stride;
  bool drawn = false;
  for (int u = s0; u <= s1; ++u) {
    const float fu = static_cast<float>(u);
    const float w = row.w_row + h(2, 0) * fu;
    // Nearest surface wins; 1/z <= 0 is behind the camera.
    if (!(w > row.zrow[u]) || w > raster.inv_near) continue;
    const float inv_w = 1.f / w;
    const float x = (row.x_row + h(0, 0) * fu) * inv_w * scale + offset;
    const float y = (row.y_row + h(1, 0) * fu) * inv_w * scale + offset;
    if (!(x >= 0.f && x < x_max && y >= 0.f && y < y_max)) continue;
    const int xi = static_cast<int>(x);
    const int yi = static_cast<int>(y);
    const float fx = x - xi, fy = y - yi;
    const float* p0 = texels + yi * stride + xi * C;
    const float* p1 = p0 + stride;
    float val[C];
    for (int c = 0; c < C; ++c) {
      const float top = p0[c] + fx * (p0[C + c] - p0[c]);
      const float bottom = p1[c] + fx * (p1[C + c] - p1[c]);
      val[c] = top + fy * (bottom - top);
    }
    const float alpha = val[C - 1];
    if (alpha < raster.alpha_min) continue;
    const float inv_alpha = 1.f / alpha;
    row.zrow[u] = w;
    uint8_t* o = row.out + u * kOut;
    for (int c = 0; c < kOut; ++c) {
      o[c] = static_cast<uint8_t>(std::min(255.f, val[c] * inv_alpha + 0.5f));
    }
    drawn = true;
  }
  return drawn;
}

// Draws rows [row0, row1] of one plane, span by span. True if any pixel
// was drawn.
template <int C>
bool DrawPlaneRows(const std::vector<Level>& levels,
                   const PlaneProjection& proj, int row0, int row1,
                   const Raster& raster) {
  const Eigen::Matrix3f h = proj.texel_from_pixel.cast<float>();
  const int num_levels = static_cast<int>(levels.size());
  bool drawn = false;
  for (int v = row0; v <= row1; ++v) {
    double lo, hi;
    PolygonRowExtent(proj.poly, proj.n, v, &lo, &hi);
    if (!(lo <= hi)) continue;
    const int col0 = std::max(0, static_cast<int>(std::floor(lo - 1)));
    const int col1 =
        std::min(raster.width - 1, static_cast<int>(std::ceil(hi + 1)));
    if (col0 > col1) continue;
    const float fv = static_cast<float>(v);
    const RowTarget row{h(0, 1) * fv + h(0, 2), h(1, 1) * fv + h(1, 2),
                        h(2, 1) * fv + h(2, 2),
                        raster.zbuf + static_cast<size_t>(v) * raster.width,
                        raster.image->ptr<uint8_t>(v)};
    for (int s0 = col0; s0 <= col1; s0 += kSpan) {
      const int s1 = std::min(col1, s0 + kSpan - 1);
      const int level = MipLevel(proj.texel_from_pixel, s0, s1, v, num_levels,
                                 raster.area_footprint, raster.mip_bias);
      if (DrawSpan<C>(levels[level], level, h, row, s0, s1, raster)) {
        drawn = true;
      }
    }
  }
  return drawn;
}

// Depth (metres, 0 for background) of rows [r_begin, r_end) from their
// inverse depths, if depth is not null; returns their foreground pixels.
int FillDepthRows(const float* zbuf, int width, int r_begin, int r_end,
                  cv::Mat* depth) {
  int foreground = 0;
  for (int v = r_begin; v < r_end; ++v) {
    const float* z = zbuf + static_cast<size_t>(v) * width;
    float* d = depth != nullptr ? depth->ptr<float>(v) : nullptr;
    for (int u = 0; u < width; ++u) {
      const bool fg = z[u] > 0.f;
      foreground += fg;
      if (d != nullptr) d[u] = fg ? 1.f / z[u] : 0.f;
    }
  }
  return foreground;
}

}  // namespace

struct Renderer::PlaneView {
  const PlaneData* plane;
  PlaneProjection proj;
};

std::vector<Renderer::PlaneView> Renderer::ViewPlanes(
    const Camera& camera, const Rigid3d& world_from_cam) const {
  const Rigid3d cam_from_world = world_from_cam.Inverse();
  const Eigen::Matrix3d rot = cam_from_world.RotationMatrix();
  const Eigen::Vector3d trans = cam_from_world.translation;
  const Eigen::Matrix3d k = camera.K();
  std::vector<PlaneView> views;
  views.reserve(planes_.size());
  for (const auto& plane : planes_) {
    PlaneProjection proj;
    if (ProjectPlane(plane->frame, plane->pixels_per_meter, plane->st_min,
                     plane->st_max, rot, trans, camera, k, options_, &proj)) {
      views.push_back({plane.get(), proj});
    }
  }
  return views;
}

template <int C>
RenderStats Renderer::RenderImpl(const Camera& camera,
                                 const Rigid3d& world_from_cam, cv::Mat* image,
                                 cv::Mat* depth) const {
  CheckOption(camera.width > 0 && camera.height > 0 && camera.fx > 0 &&
                  camera.fy > 0,
              "camera", "needs a positive size and focal lengths");
  const int width = camera.width;
  const int height = camera.height;
  image->create(height, width, C == 2 ? CV_8UC1 : CV_8UC3);
  image->setTo(cv::Scalar::all(options_.background_grey));
  if (depth != nullptr) depth->create(height, width, CV_32FC1);
  // Z-buffer of inverse depth; 0 = background (infinitely far). Kept per
  // thread so that renders do not allocate.
  thread_local std::vector<float> zbuffer;
  zbuffer.assign(static_cast<size_t>(width) * height, 0.f);
  const Raster raster{width,
                      zbuffer.data(),
                      image,
                      static_cast<float>(1.0 / options_.z_near_m),
                      static_cast<float>(options_.alpha_threshold),
                      options_.mip_bias,
                      options_.mip_footprint == MipFootprint::kArea};

  // Pass 1: the planes facing the camera. Pass 2: rows [r_begin, r_end) of
  // every plane in map order, so that a band of rows is independent of the
  // others and the result does not depend on how the rows are split.
  const std::vector<PlaneView> views = ViewPlanes(camera, world_from_cam);
  std::vector<std::atomic<bool>> drawn(views.size());
  std::atomic<int> pixels_foreground{0};
  auto draw_rows = [&](int r_begin, int r_end) {
    for (size_t pi = 0; pi < views.size(); ++pi) {
      const PlaneView& view = views[pi];
      if (DrawPlaneRows<C>(view.plane->template levels<C>(), view.proj,
                           std::max(view.proj.row0, r_begin),
                           std::min(view.proj.row1, r_end - 1), raster)) {
        drawn[pi].store(true, std::memory_order_relaxed);
      }
    }
    pixels_foreground.fetch_add(
        FillDepthRows(raster.zbuf, width, r_begin, r_end, depth),
        std::memory_order_relaxed);
  };
  // One render is serial below kParallelPixels (renders that small are
  // parallel across poses instead: RenderBatch, the particle filter).
  if (static_cast<int64_t>(width) * height >= kParallelPixels) {
    tbb::parallel_for(tbb::blocked_range<int>(0, height, 16),
                      [&](const tbb::blocked_range<int>& r) {
                        draw_rows(r.begin(), r.end());
                      });
  } else {
    draw_rows(0, height);
  }
  RenderStats stats;
  stats.planes_in_map = num_planes();
  stats.pixels_total = width * height;
  for (const std::atomic<bool>& d : drawn) stats.planes_drawn += d.load();
  stats.pixels_foreground = pixels_foreground.load();
  return stats;
}

}  // namespace monomap
