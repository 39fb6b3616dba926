#include "monomap/pipelines/demo_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <utility>

#include "monomap/eval/report_json.h"
#include "monomap/io/dataset.h"
#include "monomap/io/map_format.h"
#include "monomap/pipelines/mapping_pipeline.h"
#include "monomap/rendering/renderer.h"
#include "monomap/sim/simulate.h"
#include "monomap/sim/world.h"
#include "monomap/util/error.h"
#include "monomap/util/file.h"
#include "monomap/util/progress.h"

namespace monomap {

void DemoOptions::Check() const {
  CheckOption(!output_dir.empty(), "output_dir", "must not be empty");
  const std::vector<std::string> names = WorldNames();
  CheckOption(std::find(names.begin(), names.end(), world) != names.end(),
              "world", "unknown world '" + world + "'");
  CheckOption(num_frames >= 20, "num_frames",
              "must be at least 20 (the map needs motion)");
  CheckOption(width >= 64 && height >= 48, "width/height",
              "must be at least 64x48");
  structure.Check();
  CheckOption(rpe_delta_frames >= 1, "rpe_delta_frames", "must be at least 1");
  if (localization.enabled) localization.Check();
}

namespace {

// ---------------------------------------------------------------------------
// Small HTML / SVG helpers.

std::string Base64(const std::vector<uchar>& data) {
  static const char* kAlphabet =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((data.size() + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 2 < data.size(); i += 3) {
    const uint32_t v = (data[i] << 16) | (data[i + 1] << 8) | data[i + 2];
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += kAlphabet[v & 63];
  }
  if (i + 1 == data.size()) {
    const uint32_t v = data[i] << 16;
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += "==";
  } else if (i + 2 == data.size()) {
    const uint32_t v = (data[i] << 16) | (data[i + 1] << 8);
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += '=';
  }
  return out;
}

// An <img> with the image embedded as a base64 PNG data URI.
std::string ImgTag(const cv::Mat& image, const std::string& alt) {
  std::vector<uchar> png;
  if (image.empty() || !cv::imencode(".png", image, png)) {
    throw OutputError("demo report: cannot encode image '" + alt + "'");
  }
  return "<img alt=\"" + alt + "\" width=\"" + std::to_string(image.cols) +
         "\" height=\"" + std::to_string(image.rows) +
         "\" src=\"data:image/png;base64," + Base64(png) + "\">";
}

std::string Fmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), format, v);
  return buf;
}

std::string HtmlEscape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

// RGB in [0, 1] of a hue in [0, 1) at full saturation, 85 % value.
cv::Vec3d Hue(double h) {
  h = h - std::floor(h);
  const double v = 0.85;
  const double x = h * 6.0;
  const int i = static_cast<int>(x) % 6;
  const double f = x - std::floor(x);
  const double p = 0.0, q = v * (1 - f), t = v * f;
  switch (i) {
    case 0:
      return {v, t, p};
    case 1:
      return {q, v, p};
    case 2:
      return {p, v, t};
    case 3:
      return {p, q, v};
    case 4:
      return {t, p, v};
    default:
      return {v, p, q};
  }
}

// A distinct colour per track id (golden-ratio hue steps), as BGR.
cv::Scalar TrackColor(FeatureId id) {
  const cv::Vec3d rgb = Hue(static_cast<double>(id) * 0.6180339887);
  return cv::Scalar(rgb[2] * 255, rgb[1] * 255, rgb[0] * 255);
}

// CSS colour of a plane label; -1 (no plane) is light grey.
std::string LabelColor(int label) {
  static const char* kPalette[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728",
                                   "#9467bd", "#8c564b", "#e377c2", "#17becf",
                                   "#bcbd22", "#393b79", "#ad494a", "#637939"};
  if (label < 0) return "#c8c8c8";
  return kPalette[label % 12];
}

struct Bounds {
  double x0 = std::numeric_limits<double>::infinity();
  double y0 = std::numeric_limits<double>::infinity();
  double x1 = -std::numeric_limits<double>::infinity();
  double y1 = -std::numeric_limits<double>::infinity();
  void Add(double x, double y) {
    x0 = std::min(x0, x), x1 = std::max(x1, x);
    y0 = std::min(y0, y), y1 = std::max(y1, y);
  }
  bool Valid() const { return x0 <= x1 && y0 <= y1; }
};

// "Nice" tick step (1, 2 or 5 times a power of ten) for about 6 ticks.
double TickStep(double range) {
  if (!(range > 0)) return 1.0;
  const double raw = range / 6.0;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  const double r = raw / mag;
  return (r < 1.5 ? 1.0 : r < 3.5 ? 2.0 : r < 7.5 ? 5.0 : 10.0) * mag;
}

// An inline SVG plot with axes, in data coordinates (y up).
class SvgPlot {
 public:
  // equal_aspect: one metre is as long on both axes (maps, views); the
  // height then follows from the data, capped at max_height.
  SvgPlot(Bounds b, int width, int max_height, bool equal_aspect,
          std::string x_label, std::string y_label)
      : x_label_(std::move(x_label)), y_label_(std::move(y_label)) {
    if (!b.Valid()) b = Bounds{0, 0, 1, 1};
    const double pad_x = std::max(1e-6, 0.03 * (b.x1 - b.x0));
    const double pad_y = std::max(1e-6, 0.05 * (b.y1 - b.y0));
    b.x0 -= pad_x, b.x1 += pad_x, b.y0 -= pad_y, b.y1 += pad_y;
    const double pw = width - kLeft - kRight;
    double ph = max_height - kTop - kBottom;
    sx_ = pw / (b.x1 - b.x0);
    sy_ = ph / (b.y1 - b.y0);
    if (equal_aspect) {
      const double s = std::min(sx_, sy_);
      sx_ = sy_ = s;
      // Centre the data horizontally; shrink the height to the data.
      const double used_w = s * (b.x1 - b.x0);
      const double extra = (pw - used_w) / s / 2;
      b.x0 -= extra, b.x1 += extra;
      ph = s * (b.y1 - b.y0);
    }
    b_ = b;
    width_ = width;
    height_ = static_cast<int>(std::ceil(ph + kTop + kBottom));
  }

  double X(double x) const { return kLeft + (x - b_.x0) * sx_; }
  double Y(double y) const { return kTop + (b_.y1 - y) * sy_; }

  // Round dots (one path per colour keeps the page small).
  void Dots(const std::vector<Eigen::Vector2d>& points,
            const std::vector<int>& labels, double radius) {
    std::map<int, std::string> paths;
    for (size_t i = 0; i < points.size(); ++i) {
      char buf[48];
      std::snprintf(buf, sizeof(buf), "M%.1f %.1fh0", X(points[i].x()),
                    Y(points[i].y()));
      paths[labels[i]] += buf;
    }
    for (const auto& [label, d] : paths) {
      body_ << "<path d=\"" << d << "\" stroke=\"" << LabelColor(label)
            << "\" stroke-width=\"" << 2 * radius
            << "\" stroke-linecap=\"round\" fill=\"none\"/>\n";
    }
  }

  void Line(const std::vector<Eigen::Vector2d>& points,
            const std::string& colour, double width,
            const std::string& dash = "") {
    if (points.empty()) return;
    body_ << "<polyline fill=\"none\" stroke=\"" << colour
          << "\" stroke-width=\"" << width << "\"";
    if (!dash.empty()) body_ << " stroke-dasharray=\"" << dash << "\"";
    body_ << " points=\"";
    for (const auto& p : points) {
      char buf[48];
      std::snprintf(buf, sizeof(buf), "%.1f,%.1f ", X(p.x()), Y(p.y()));
      body_ << buf;
    }
    body_ << "\"/>\n";
  }

  void Marker(const Eigen::Vector2d& p, const std::string& colour,
              const std::string& text) {
    body_ << "<circle cx=\"" << X(p.x()) << "\" cy=\"" << Y(p.y())
          << "\" r=\"4\" fill=\"" << colour << "\"/><text x=\"" << X(p.x()) + 6
          << "\" y=\"" << Y(p.y()) - 6 << "\" font-size=\"11\">"
          << HtmlEscape(text) << "</text>\n";
  }

  // Legend entries (colour, text) in the top-right corner.
  void Legend(const std::vector<std::pair<std::string, std::string>>& items) {
    double y = kTop + 14;
    for (const auto& [colour, text] : items) {
      const double x = width_ - kRight - 150;
      body_ << "<rect x=\"" << x << "\" y=\"" << y - 9
            << "\" width=\"14\" height=\"10\" fill=\"" << colour
            << "\"/><text x=\"" << x + 19 << "\" y=\"" << y
            << "\" font-size=\"12\">" << HtmlEscape(text) << "</text>\n";
      y += 16;
    }
  }

  std::string Finish() const {
    std::ostringstream s;
    s << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width_
      << "\" height=\"" << height_ << "\" viewBox=\"0 0 " << width_ << " "
      << height_ << "\" font-family=\"sans-serif\">\n";
    s << "<rect x=\"" << kLeft << "\" y=\"" << kTop << "\" width=\""
      << width_ - kLeft - kRight << "\" height=\"" << height_ - kTop - kBottom
      << "\" fill=\"#fbfbfb\" stroke=\"#999\"/>\n";
    // Ticks and grid.
    const double xs = TickStep(b_.x1 - b_.x0), ys = TickStep(b_.y1 - b_.y0);
    for (double x = std::ceil(b_.x0 / xs) * xs; x <= b_.x1; x += xs) {
      s << "<line x1=\"" << X(x) << "\" y1=\"" << kTop << "\" x2=\"" << X(x)
        << "\" y2=\"" << height_ - kBottom
        << "\" stroke=\"#e4e4e4\"/><text x=\"" << X(x) << "\" y=\""
        << height_ - kBottom + 14
        << "\" font-size=\"11\" text-anchor=\"middle\">"
        << Fmt("%g", std::abs(x) < 1e-9 ? 0.0 : x) << "</text>\n";
    }
    for (double y = std::ceil(b_.y0 / ys) * ys; y <= b_.y1; y += ys) {
      s << "<line x1=\"" << kLeft << "\" y1=\"" << Y(y) << "\" x2=\""
        << width_ - kRight << "\" y2=\"" << Y(y)
        << "\" stroke=\"#e4e4e4\"/><text x=\"" << kLeft - 4 << "\" y=\""
        << Y(y) + 4 << "\" font-size=\"11\" text-anchor=\"end\">"
        << Fmt("%g", std::abs(y) < 1e-9 ? 0.0 : y) << "</text>\n";
    }
    s << "<text x=\"" << (kLeft + width_ - kRight) / 2.0 << "\" y=\""
      << height_ - 4 << "\" font-size=\"12\" text-anchor=\"middle\">"
      << HtmlEscape(x_label_) << "</text>\n";
    s << "<text x=\"12\" y=\"" << (kTop + height_ - kBottom) / 2.0
      << "\" font-size=\"12\" text-anchor=\"middle\" transform=\"rotate(-90 "
         "12 "
      << (kTop + height_ - kBottom) / 2.0 << ")\">" << HtmlEscape(y_label_)
      << "</text>\n";
    // Clip the data to the plot area (outlines may reach beyond it).
    static int next_clip_id = 0;
    const std::string clip = "clip" + std::to_string(next_clip_id++);
    s << "<clipPath id=\"" << clip << "\"><rect x=\"" << kLeft << "\" y=\""
      << kTop << "\" width=\"" << width_ - kLeft - kRight << "\" height=\""
      << height_ - kTop - kBottom << "\"/></clipPath>\n<g clip-path=\"url(#"
      << clip << ")\">\n"
      << body_.str() << "</g>\n</svg>\n";
    return s.str();
  }

 private:
  static constexpr int kLeft = 56, kRight = 12, kTop = 10, kBottom = 36;
  Bounds b_;
  double sx_ = 1, sy_ = 1;
  int width_ = 0, height_ = 0;
  std::string x_label_, y_label_;
  std::ostringstream body_;
};

// ---------------------------------------------------------------------------
// Evaluation helpers.

std::vector<TimedPose> AlignedPoses(const std::vector<TimedPose>& poses,
                                    const Sim3d& align) {
  std::vector<TimedPose> out = poses;
  for (auto& p : out) {
    p.world_from_cam.translation =
        align.rigid * (align.scale * p.world_from_cam.translation);
    p.world_from_cam.rotation =
        align.rigid.rotation * p.world_from_cam.rotation;
  }
  return out;
}

// Per matched frame: (frame index in gt, position error) after alignment.
std::vector<Eigen::Vector2d> PerFramePositionError(
    const std::vector<TimedPose>& aligned_estimate,
    const std::vector<TimedPose>& groundtruth) {
  std::vector<Eigen::Vector2d> out;
  for (const auto& [e, g] :
       AssociateByTimestamp(aligned_estimate, groundtruth)) {
    out.emplace_back(static_cast<double>(g),
                     (aligned_estimate[e].world_from_cam.translation -
                      groundtruth[g].world_from_cam.translation)
                         .norm());
  }
  return out;
}

bool TexturesAreColour(const std::vector<TexturedPlane>& planes) {
  for (const auto& p : planes) {
    if (p.texture.empty() || p.texture.channels() < 3) continue;
    const int step = std::max(1, p.texture.rows / 64);
    for (int r = 0; r < p.texture.rows; r += step) {
      for (int c = 0; c < p.texture.cols; c += 3) {
        const uchar* px = p.texture.ptr<uchar>(r) + c * p.texture.channels();
        if (p.texture.channels() == 4 && px[3] == 0) continue;
        if (std::abs(px[0] - px[1]) > 2 || std::abs(px[1] - px[2]) > 2) {
          return true;
        }
      }
    }
  }
  return false;
}

// The raw image resampled to the (undistorted) pinhole camera `pinhole`,
// so that it can be compared with a render.
cv::Mat UndistortTo(const cv::Mat& raw, const Camera& camera,
                    const Camera& pinhole) {
  cv::Mat map_x(pinhole.height, pinhole.width, CV_32FC1);
  cv::Mat map_y(pinhole.height, pinhole.width, CV_32FC1);
  for (int v = 0; v < pinhole.height; ++v) {
    for (int u = 0; u < pinhole.width; ++u) {
      const Eigen::Vector2d xn((u - pinhole.cx) / pinhole.fx,
                               (v - pinhole.cy) / pinhole.fy);
      const Eigen::Vector2d px =
          camera.PinholeFromNormalized(camera.Distort(xn));
      map_x.at<float>(v, u) = static_cast<float>(px.x());
      map_y.at<float>(v, u) = static_cast<float>(px.y());
    }
  }
  cv::Mat out;
  cv::remap(raw, out, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  return out;
}

std::string StatsRow(const std::string& name, const ErrorStats& s, double scale,
                     const char* format) {
  std::string row = "<tr><td>" + HtmlEscape(name) + "</td><td>" +
                    std::to_string(s.count) + "</td>";
  for (double v : {s.mean, s.median, s.p90, s.max, s.rms}) {
    row += "<td>" + Fmt(format, v * scale) + "</td>";
  }
  return row + "</tr>\n";
}

const char* kStatsHeader =
    "<tr><th></th><th>count</th><th>mean</th><th>median</th><th>p90</th>"
    "<th>max</th><th>rms</th></tr>\n";

// The localization section: figures of both methods, the map's texture
// fidelity on the traversal, error and particle count per update, and the
// particles converging (top views at a few updates).
std::string LocalizationSection(const DemoLocalization& loc,
                                const DemoLocalizationOptions& options) {
  static const char* kColours[] = {"#d62728", "#1f77b4"};
  std::ostringstream h;
  h << "<h2 id=\"localization\">Localization</h2>\n<p class=\"note\">A "
       "second traversal of the same world ("
    << loc.frames << " frames, other odometry errors and image noise, "
    << Fmt("%g", options.start_offset_m) << " m into the mapped path and "
    << Fmt("%g", options.lateral_offset_m)
    << " m beside it), localized in the map from a global initialisation "
       "(particles over the whole mapped area, planar state) with plain "
       "Monte Carlo Localization and with Monte Carlo Correction, both with "
       "a budget of "
    << options.particles << " particles. Localized = position within "
    << Fmt("%g", options.accuracy.max_translation_error_m * 100)
    << " cm and heading within "
    << Fmt("%g", options.accuracy.max_rotation_error_deg)
    << "&deg; of the ground truth. One run with the demo's seed; the success "
       "rates over 20 seeds are in docs/benchmarks.md.</p>\n";
  h << "<table><tr><th>method</th><th>localized at the end</th>"
       "<th>converged at update</th><th>final error</th>"
       "<th>mean error after convergence</th><th>updates localized</th>"
       "<th>mean particles</th><th>ms per update</th></tr>\n";
  for (const DemoLocalizationRun& r : loc.runs) {
    const LocalizationAccuracy& a = r.accuracy;
    h << "<tr><td>" << r.name << "</td><td class=\""
      << (a.success ? "ok\">yes" : "bad\">no") << "</td><td>"
      << (a.converged_step >= 0 ? std::to_string(a.converged_step) : "-")
      << "</td><td>" << Fmt("%.1f cm", 100 * a.final_translation_error_m)
      << ", " << Fmt("%.2f&deg;", a.final_rotation_error_deg) << "</td><td>"
      << (a.success ? Fmt("%.1f cm", 100 * a.mean_translation_error_m) + ", " +
                          Fmt("%.2f&deg;", a.mean_rotation_error_deg)
                    : std::string("-"))
      << "</td><td>" << Fmt("%.0f%%", 100 * a.fraction_within) << "</td><td>"
      << Fmt("%.0f", r.report.mean_particles) << "</td><td>"
      << Fmt("%.1f", 1e3 * r.report.mean_step_seconds) << "</td></tr>\n";
  }
  h << "</table>\n";

  const RenderFidelity& f = loc.fidelity;
  h << "<h3>Texture fidelity</h3>\n<p class=\"note\">The map rendered from "
       "the traversal's ground-truth poses (which the map was not built "
       "from) against the real images, every "
    << options.fidelity_stride
    << "th frame, over the pixels the map covers: " << f.frames.size()
    << " frames compared, " << f.skipped << " skipped (map covers less than "
    << Fmt("%.0f%%", 100 * options.fidelity.min_coverage)
    << "). PSNR after a least-squares gain and offset.</p>\n<table>"
    << kStatsHeader << StatsRow("NCC", f.ncc, 1, "%.3f")
    << StatsRow("PSNR (dB)", f.psnr_db, 1, "%.1f")
    << StatsRow("coverage (%)", f.coverage, 100, "%.0f") << "</table>\n";

  // Error and particle count per update.
  Bounds eb, pb;
  eb.Add(0, 0);
  pb.Add(0, 0);
  std::vector<std::vector<Eigen::Vector2d>> err(loc.runs.size()),
      count(loc.runs.size());
  for (size_t m = 0; m < loc.runs.size(); ++m) {
    const LocalizationAccuracy& a = loc.runs[m].accuracy;
    for (size_t i = 0; i < a.step.size(); ++i) {
      // Capped so that the converged part stays readable.
      const double cm = std::min(100.0, 100 * a.translation_error_m[i]);
      err[m].emplace_back(a.step[i], cm);
      eb.Add(a.step[i], cm);
    }
    const auto& steps = loc.runs[m].report.steps;
    for (size_t i = 0; i < steps.size(); ++i) {
      count[m].emplace_back(i, steps[i].particles);
      pb.Add(i, steps[i].particles);
    }
  }
  SvgPlot err_plot(eb, 660, 300, false, "update",
                   "position error (cm, capped at 100)");
  SvgPlot count_plot(pb, 660, 300, false, "update", "particles");
  std::vector<std::pair<std::string, std::string>> legend;
  for (size_t m = 0; m < loc.runs.size(); ++m) {
    err_plot.Line(err[m], kColours[m % 2], 1.5);
    count_plot.Line(count[m], kColours[m % 2], 1.5);
    legend.emplace_back(kColours[m % 2], loc.runs[m].name);
  }
  err_plot.Legend(legend);
  count_plot.Legend(legend);
  h << "<div class=\"row\"><figure>" << err_plot.Finish()
    << "<figcaption>Position error of the estimate per update."
       "</figcaption></figure><figure>"
    << count_plot.Finish()
    << "<figcaption>Particles alive per update (KLD-sampling; MCC merges "
       "duplicates).</figcaption></figure></div>\n";

  // Top views of the particles at a few updates.
  Bounds area;
  for (const DemoLocalizationRun& r : loc.runs) {
    if (r.particles_xy.empty()) continue;
    for (const auto& p : r.particles_xy.front()) area.Add(p.x(), p.y());
  }
  for (const TimedPose& g : loc.groundtruth) {
    area.Add(g.world_from_cam.translation.x(),
             g.world_from_cam.translation.y());
  }
  std::vector<Eigen::Vector2d> path;
  for (const TimedPose& g : loc.groundtruth) {
    path.emplace_back(g.world_from_cam.translation.head<2>());
  }
  for (size_t m = 0; m < loc.runs.size(); ++m) {
    const DemoLocalizationRun& r = loc.runs[m];
    const int n = static_cast<int>(r.particles_xy.size());
    if (n == 0) continue;
    std::vector<int> shown = {0, 2, 5, 15, n - 1};
    shown.erase(std::remove_if(shown.begin(), shown.end(),
                               [&](int s) { return s >= n; }),
                shown.end());
    shown.erase(std::unique(shown.begin(), shown.end()), shown.end());
    h << "<h3>" << r.name << ": particles (camera positions, top view)</h3>\n"
      << "<div class=\"row\">\n";
    for (int s : shown) {
      SvgPlot plot(area, 330, 330, true, "x (m)", "y (m)");
      plot.Line(path, "#bbb", 1.0);
      const std::vector<int> labels(r.particles_xy[s].size(),
                                    static_cast<int>(m));
      plot.Dots(r.particles_xy[s], labels, 1.3);
      if (s < static_cast<int>(loc.groundtruth.size())) {
        plot.Marker(loc.groundtruth[s].world_from_cam.translation.head<2>(),
                    "#000", "truth");
      }
      h << "<figure>" << plot.Finish() << "<figcaption>Update " << s << ": "
        << r.report.steps[s].particles << " particles"
        << "</figcaption></figure>\n";
    }
    h << "</div>\n";
  }
  return h.str();
}

const char* kCss = R"(
body{font-family:sans-serif;margin:24px auto;max-width:1400px;color:#222;
line-height:1.4;padding:0 16px}
h1{margin-bottom:4px} h2{border-bottom:2px solid #ddd;padding-bottom:4px;
margin-top:36px}
.cards{display:flex;flex-wrap:wrap;gap:12px;margin:16px 0}
.card{background:#f3f6fa;border:1px solid #d5dde8;border-radius:6px;
padding:10px 16px;min-width:150px}
.card b{display:block;font-size:22px}
.row{display:flex;flex-wrap:wrap;gap:16px;align-items:flex-start}
figure{margin:0 0 12px 0} figcaption{font-size:13px;color:#555;
max-width:660px}
table{border-collapse:collapse;margin:8px 0 16px 0;font-size:14px}
td,th{border:1px solid #ccc;padding:3px 9px;text-align:right}
td:first-child,th:first-child{text-align:left}
tr:nth-child(even){background:#f7f7f7}
.tex{background:repeating-conic-gradient(#ddd 0 25%,#fff 0 50%) 0 0/16px 16px;
border:1px solid #ccc}
.ok{color:#1a7f37} .bad{color:#c62828}
.note{font-size:13px;color:#555}
)";

// Inline script the headless check reads: counts decoded images and
// JavaScript errors into data attributes of <body>.
const char* kCheckScript = R"(
<script>
(function(){
  var errors = 0;
  window.addEventListener('error', function(){ errors++;
    document.body.setAttribute('data-js-errors', String(errors)); });
  function count(){
    var imgs = document.images, ok = 0;
    for (var i = 0; i < imgs.length; i++)
      if (imgs[i].complete && imgs[i].naturalWidth > 0) ok++;
    document.body.setAttribute('data-images-total', String(imgs.length));
    document.body.setAttribute('data-images-decoded', String(ok));
    document.body.setAttribute('data-js-errors', String(errors));
  }
  window.addEventListener('load', count);
})();
</script>
)";

}  // namespace

nlohmann::json DemoReport::ToJson() const {
  nlohmann::json j;
  j["paths"] = {{"report_html", report_html.string()},
                {"report_json", report_json.string()},
                {"dataset", dataset_dir.string()},
                {"map", map_dir.string()}};
  // The structure figures under the keys report.json has always had
  // (counts, point_error, planes); the per-true-plane list of the eval
  // JSON is not part of it.
  const nlohmann::json s = monomap::ToJson(structure);
  j["counts"] = s["counts"];
  j["counts"]["frames"] = frames;
  j["counts"]["tracks"] = tracks;
  j["counts"]["landmarks"] = landmarks;
  j["point_error"] = s["point_error"];
  j["planes"] = s["planes"];
  j["trajectory"] = {{"alignment", "first_pose"},
                     {"ate_refined", monomap::ToJson(ate_refined)},
                     {"ate_odometry", monomap::ToJson(ate_odometry)},
                     {"rpe_refined", monomap::ToJson(rpe_refined)},
                     {"rpe_odometry", monomap::ToJson(rpe_odometry)}};
  j["mapping"] = mapping;
  if (!localization.runs.empty()) j["localization"] = localization.ToJson();
  j["timings_seconds"] = {{"simulate", simulate_seconds},
                          {"mapping", mapping_seconds},
                          {"evaluation", evaluation_seconds},
                          {"localization", localization.seconds},
                          {"report", report_seconds},
                          {"total", total_seconds}};
  return j;
}

DemoReport RunDemo(const DemoOptions& options) {
  options.Check();
  const Timer total_timer;
  auto say = [&](const std::string& text) {
    if (options.show_progress) std::fprintf(stderr, "demo: %s\n", text.c_str());
  };
  DemoReport report;
  const std::filesystem::path dir = options.output_dir;
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) {
    throw OutputError("cannot create " + dir.string() + ": " + ec.message());
  }
  report.dataset_dir = dir / "dataset";
  report.map_dir = dir / "map";
  report.report_html = dir / "report.html";
  report.report_json = dir / "report.json";

  // 1. Simulate.
  say("simulating " + options.world + " (" +
      std::to_string(options.num_frames) + " frames) -> " +
      report.dataset_dir.string());
  SimulationOptions sim;
  sim.world = options.world;
  sim.seed = options.seed;
  sim.num_frames = options.num_frames;
  sim.width = options.width;
  sim.height = options.height;
  sim.show_progress = options.show_progress;
  const SimulationReport sim_report = Simulate(sim, report.dataset_dir);
  report.simulate_seconds = sim_report.seconds;

  // 2. Build the map from images and odometry only.
  Dataset dataset = LoadDataset(report.dataset_dir);
  if (!dataset.has_groundtruth) {
    throw StageError("demo: the simulated dataset has no ground truth");
  }
  std::vector<TimedPose> groundtruth, odometry;
  for (auto& f : dataset.frames) {
    groundtruth.push_back({f.timestamp, *f.groundtruth_world_from_cam});
    odometry.push_back({f.timestamp, f.odometry_world_from_cam});
  }
  Dataset blind = dataset;  // the pipeline never sees ground truth
  blind.has_groundtruth = false;
  for (auto& f : blind.frames) f.groundtruth_world_from_cam.reset();

  say("building the map -> " + report.map_dir.string());
  MappingOptions mapping_options;
  mapping_options.show_progress = options.show_progress;
  const Timer mapping_timer;
  const MappingResult result = BuildMap(blind, mapping_options);
  WriteMappingResult(report.map_dir, result);
  report.mapping_seconds = mapping_timer.ElapsedSeconds();
  report.mapping = result.report.ToJson();
  const Map& map = result.map;
  report.frames = static_cast<int>(dataset.frames.size());
  report.tracks = static_cast<int>(result.tracks.size());
  report.landmarks = static_cast<int>(map.landmarks.size());

  // 3. Evaluate. The map lives in the odometry frame; both odometry and
  // ground truth start at the same pose, and the first-pose alignment of the
  // odometry makes any residual offset explicit.
  say("evaluating against the ground truth");
  const Timer eval_timer;
  const Map truth = ReadMap(report.dataset_dir / "structure");
  const Sim3d world_from_map =
      AlignTrajectories(odometry, groundtruth, Alignment::kFirstPose);

  // 3a. Points and planes.
  report.structure =
      EvaluateStructure(map, truth, world_from_map.rigid, options.structure);
  const StructureAccuracy& structure = report.structure;

  // 3b. Trajectories.
  report.ate_refined = AbsoluteTrajectoryError(map.trajectory, groundtruth,
                                               Alignment::kFirstPose);
  report.ate_odometry =
      AbsoluteTrajectoryError(odometry, groundtruth, Alignment::kFirstPose);
  const int delta =
      std::min(options.rpe_delta_frames, std::max(1, report.frames - 1));
  report.rpe_refined = RelativePoseError(map.trajectory, groundtruth, delta);
  report.rpe_odometry = RelativePoseError(odometry, groundtruth, delta);
  const std::vector<TimedPose> refined_aligned = AlignedPoses(
      map.trajectory,
      AlignTrajectories(map.trajectory, groundtruth, Alignment::kFirstPose));
  const std::vector<TimedPose> odometry_aligned =
      AlignedPoses(odometry, world_from_map);
  report.evaluation_seconds = eval_timer.ElapsedSeconds();

  // 3c. A second traversal localized in the map.
  if (options.localization.enabled) {
    say("localizing a second traversal (MCL and MCC, global start)");
    report.localization =
        RunDemoLocalization(map, sim, world_from_map.rigid.Inverse(),
                            options.localization, dir / "localization_dataset");
  }

  // 4. Figures and the page.
  say("writing the report");
  const Timer report_timer;
  const int n = report.frames;
  std::ostringstream h;
  h << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
       "<title>monomap demo: "
    << HtmlEscape(options.world) << "</title><style>" << kCss
    << "</style></head>\n<body>\n";
  h << "<h1>monomap demo: " << HtmlEscape(options.world) << "</h1>\n"
    << "<p class=\"note\">Simulated " << n << " frames of " << options.width
    << "x" << options.height << " (seed " << options.seed
    << "), built a map from the images and the odometry only, and compared "
       "it with the simulator's exact ground truth. Dataset: <code>"
    << HtmlEscape(report.dataset_dir.string()) << "</code>, map: <code>"
    << HtmlEscape(report.map_dir.string()) << "</code>.</p>\n";

  const PointAccuracy& pe = structure.point_error_on_planes;
  h << "<div class=\"cards\">"
    << "<div class=\"card\">landmarks<b>" << report.landmarks << "</b></div>"
    << "<div class=\"card\">planes found / observed<b>"
    << structure.fitted_planes << " / " << structure.observed_true_planes
    << "</b></div>"
    << "<div class=\"card\">plane recall / precision<b>"
    << Fmt("%.0f%%", 100 * structure.recall) << " / "
    << Fmt("%.0f%%", 100 * structure.precision) << "</b></div>"
    << "<div class=\"card\">median point error (on planes)<b>"
    << Fmt("%.1f mm", pe.absolute_m.median * 1000) << " · "
    << Fmt("%.2f%%", pe.relative_percent.median) << "</b></div>"
    << "<div class=\"card\">ATE refined / odometry (rms)<b>"
    << Fmt("%.1f", report.ate_refined.translation_m.rms * 100) << " / "
    << Fmt("%.1f cm", report.ate_odometry.translation_m.rms * 100)
    << "</b></div>"
    << "<div class=\"card\">total time<b>"
    << Fmt("%.1f s", total_timer.ElapsedSeconds()) << "</b></div>"
    << "</div>\n";

  // (a) Tracked features on three frames.
  h << "<h2 id=\"tracks\">Tracked features</h2>\n<div class=\"row\">\n";
  {
    const std::vector<int> frames = {n / 4, n / 2, 3 * n / 4};
    constexpr int kTail = 10;  // frames of history drawn per track
    for (int f : frames) {
      cv::Mat image = dataset.LoadImage(f, /*color=*/true);
      int drawn = 0;
      for (const Track& t : result.tracks) {
        if (t.observations.empty() || t.observations.front().frame > f ||
            t.observations.back().frame < f) {
          continue;
        }
        std::vector<cv::Point> line;
        for (const Observation& o : t.observations) {
          if (o.frame < f - kTail || o.frame > f) continue;
          line.emplace_back(cvRound(o.px.x() * 4), cvRound(o.px.y() * 4));
        }
        if (line.empty()) continue;
        const cv::Scalar colour = TrackColor(t.id);
        cv::polylines(image, line, false, colour, 1, cv::LINE_AA, 2);
        cv::circle(image, line.back(), 2 * 4, colour, 1, cv::LINE_AA, 2);
        ++drawn;
      }
      h << "<figure>" << ImgTag(image, "tracks at frame " + std::to_string(f))
        << "<figcaption>Frame " << f << ": " << drawn
        << " tracks, with their last " << kTail
        << " frames (colour = track id).</figcaption></figure>\n";
    }
  }
  h << "</div>\n";

  // (b) Point cloud, top and side views, coloured by plane.
  h << "<h2 id=\"points\">Point cloud by plane</h2>\n";
  {
    std::vector<Eigen::Vector3d> xs;
    std::vector<int> labels;
    // At most 12000 points keep the page light; a fixed stride keeps it
    // deterministic.
    const size_t stride = std::max<size_t>(1, map.landmarks.size() / 12000);
    for (size_t i = 0; i < map.landmarks.size(); i += stride) {
      xs.push_back(world_from_map.rigid * map.landmarks[i].x_in_world);
      labels.push_back(map.landmarks[i].plane_id);
    }
    // Views span the central 99 % of the points: a few wild outliers must
    // not shrink the structure to a dot.
    auto robust_range = [&](int axis, double* lo, double* hi) {
      std::vector<double> v;
      for (const auto& x : xs) v.push_back(x[axis]);
      for (const auto& p : groundtruth) {
        v.push_back(p.world_from_cam.translation[axis]);
      }
      std::sort(v.begin(), v.end());
      *lo = v[static_cast<size_t>(0.005 * (v.size() - 1))];
      *hi = v[static_cast<size_t>(0.995 * (v.size() - 1))];
    };
    double x0, x1, y0, y1, z0, z1;
    robust_range(0, &x0, &x1);
    robust_range(1, &y0, &y1);
    robust_range(2, &z0, &z1);
    // Side view along the longer horizontal axis.
    const int side_axis = (x1 - x0) >= (y1 - y0) ? 0 : 1;
    auto view = [&](int ax, int ay, double a0, double a1, double b0, double b1,
                    const std::string& lx, const std::string& ly, int max_h) {
      Bounds b;
      b.Add(a0, b0);
      b.Add(a1, b1);
      SvgPlot plot(b, 660, max_h, true, lx, ly);
      std::vector<Eigen::Vector2d> pts;
      std::vector<int> lab;
      for (size_t i = 0; i < xs.size(); ++i) {
        if (xs[i][ax] < a0 || xs[i][ax] > a1 || xs[i][ay] < b0 ||
            xs[i][ay] > b1) {
          continue;
        }
        pts.emplace_back(xs[i][ax], xs[i][ay]);
        lab.push_back(labels[i]);
      }
      // Outlines of the true planes (ground truth) under the points.
      for (const TexturedPlane& t : truth.planes) {
        std::vector<Eigen::Vector2d> outline;
        for (const auto& st : t.polygon) {
          const Eigen::Vector3d x = t.frame.ToWorld(st);
          outline.emplace_back(x[ax], x[ay]);
        }
        if (!outline.empty()) outline.push_back(outline.front());
        plot.Line(outline, "#777", 1.0, "3,3");
      }
      plot.Dots(pts, lab, 1.3);
      std::vector<Eigen::Vector2d> cams;
      for (const auto& p : refined_aligned) {
        cams.emplace_back(p.world_from_cam.translation[ax],
                          p.world_from_cam.translation[ay]);
      }
      plot.Line(cams, "#000", 1.5);
      return plot.Finish();
    };
    h << "<div class=\"row\"><figure>"
      << view(0, 1, x0, x1, y0, y1, "x (m)", "y (m)", 560)
      << "<figcaption>Top view (x-y). Black: refined camera path; dashed: "
         "true planes. Colour: plane label, grey: on no plane."
         "</figcaption></figure>\n<figure>"
      << view(side_axis, 2, side_axis == 0 ? x0 : y0, side_axis == 0 ? x1 : y1,
              z0, z1, side_axis == 0 ? "x (m)" : "y (m)", "z (m)", 400)
      << "<figcaption>Side view (" << (side_axis == 0 ? "x" : "y")
      << "-z).</figcaption></figure></div>\n";
    h << "<p>";
    for (const auto& p : map.planes) {
      h << "<span style=\"color:" << LabelColor(p.id) << "\">&#9632;</span> "
        << "plane " << p.id << " &nbsp; ";
    }
    h << "<span style=\"color:" << LabelColor(-1)
      << "\">&#9632;</span> no plane</p>\n";
  }

  // (c) Plane textures.
  h << "<h2 id=\"textures\">Plane textures</h2>\n<div class=\"row\">\n";
  for (const TexturedPlane& p : map.planes) {
    if (p.texture.empty()) continue;
    cv::Mat tex = p.texture;
    if (tex.cols > 512) {
      const double s = 512.0 / tex.cols;
      cv::resize(tex, tex, cv::Size(512, std::max(1, cvRound(tex.rows * s))), 0,
                 0, cv::INTER_AREA);
    }
    const PlaneMatch* m = nullptr;
    for (const auto& pm : structure.matches) {
      if (pm.fitted_id == p.id) m = &pm;
    }
    h << "<figure><div class=\"tex\" style=\"display:inline-block\">"
      << ImgTag(tex, "texture of plane " + std::to_string(p.id))
      << "</div><figcaption><span style=\"color:" << LabelColor(p.id)
      << "\">&#9632;</span> Plane " << p.id << ": " << p.texture.cols << "x"
      << p.texture.rows << " texels at " << Fmt("%.0f", p.pixels_per_meter)
      << " px/m" << (m ? ", " + std::to_string(m->inliers) + " points" : "")
      << "</figcaption></figure>\n";
  }
  h << "</div>\n";

  // (d) Renders of the map next to the real (undistorted) images.
  h << "<h2 id=\"renders\">Map rendered from ground-truth poses</h2>\n";
  {
    RendererOptions ropt;
    ropt.enable_color = TexturesAreColour(map.planes);
    ropt.background_grey = 40;
    const Renderer renderer(map, ropt);
    const Camera small =
        dataset.camera.Pinhole().Scaled(options.width / 2, options.height / 2);
    const Rigid3d map_from_world = world_from_map.rigid.Inverse();
    h << "<p class=\"note\">Left: the real image, undistorted. Right: the "
         "map's textured planes rendered from the ground-truth pose ("
      << (ropt.enable_color ? "colour" : "grey")
      << "; dark = no plane). Difference: mean absolute grey difference "
         "where the map has a plane.</p>\n";
    for (int f : {n / 6, n / 2, 5 * n / 6}) {
      const Rigid3d pose = map_from_world * groundtruth[f].world_from_cam;
      cv::Mat render;
      RenderStats stats;
      if (ropt.enable_color) {
        stats = renderer.RenderColor(small, pose, &render);
      } else {
        stats = renderer.Render(small, pose, &render);
      }
      const cv::Mat real = UndistortTo(dataset.LoadImage(f, ropt.enable_color),
                                       dataset.camera, small);
      cv::Mat real_grey = real, render_grey = render;
      if (real.channels() == 3) {
        cv::cvtColor(real, real_grey, cv::COLOR_BGR2GRAY);
        cv::cvtColor(render, render_grey, cv::COLOR_BGR2GRAY);
      }
      cv::Mat depth;
      renderer.Render(small, pose, &render_grey, &depth);
      cv::Mat diff;
      cv::absdiff(real_grey, render_grey, diff);
      const cv::Scalar mean_diff = cv::mean(diff, depth > 0);
      const double coverage =
          stats.pixels_total > 0
              ? 100.0 * stats.pixels_foreground / stats.pixels_total
              : 0.0;
      h << "<div class=\"row\"><figure>" << ImgTag(real, "real frame")
        << "<figcaption>Frame " << f << " (real)</figcaption></figure>"
        << "<figure>" << ImgTag(render, "render")
        << "<figcaption>Render: " << stats.planes_drawn << " planes, "
        << Fmt("%.0f%%", coverage) << " of the image covered, difference "
        << Fmt("%.1f", mean_diff[0]) << " grey levels</figcaption></figure>"
        << "</div>\n";
    }
  }

  // (e) Error figures.
  h << "<h2 id=\"accuracy\">Accuracy</h2>\n<h3>Points</h3>\n"
    << "<p class=\"note\">Distance of each landmark to the nearest true "
       "plane containing its projection; relative = distance / mean depth. "
    << structure.landmarks_off_structure
    << " landmarks project onto no true plane and are not counted.</p>\n"
    << "<table>" << kStatsHeader
    << StatsRow("all landmarks (mm)", structure.point_error_all.absolute_m,
                1000, "%.1f")
    << StatsRow("all landmarks (%)", structure.point_error_all.relative_percent,
                1, "%.2f")
    << StatsRow("on a fitted plane (mm)",
                structure.point_error_on_planes.absolute_m, 1000, "%.1f")
    << StatsRow("on a fitted plane (%)",
                structure.point_error_on_planes.relative_percent, 1, "%.2f")
    << "</table>\n";
  h << "<h3>Planes</h3>\n<p class=\"note\">A fitted plane matches a true "
       "plane if the normals differ by at most "
    << Fmt("%g", options.structure.max_match_angle_deg)
    << "&deg; and the offsets by at most "
    << Fmt("%g", options.structure.max_match_offset_m * 100) << " cm. "
    << structure.true_planes << " true planes, "
    << structure.observed_true_planes << " observed (&ge; "
    << options.structure.min_observed_landmarks << " landmarks within "
    << Fmt("%g", options.structure.observed_distance_m * 100) << " cm). Recall "
    << Fmt("%.0f%%", 100 * structure.recall) << ", precision "
    << Fmt("%.0f%%", 100 * structure.precision)
    << ".</p>\n<table><tr><th>fitted plane</th><th>points</th><th>true "
       "plane</th><th>normal error (&deg;)</th><th>offset error "
       "(mm)</th><th>match</th></tr>\n";
  for (const auto& m : structure.matches) {
    h << "<tr><td><span style=\"color:" << LabelColor(m.fitted_id)
      << "\">&#9632;</span> " << m.fitted_id << "</td><td>" << m.inliers
      << "</td><td>" << m.true_id << "</td><td>"
      << Fmt("%.2f", m.normal_error_deg) << "</td><td>"
      << Fmt("%.1f", m.offset_error_m * 1000) << "</td><td class=\""
      << (m.matched ? "ok\">yes" : "bad\">no") << "</td></tr>\n";
  }
  h << "</table>\n";
  auto traj_rows = [&](const std::string& name, const TrajectoryErrors& e) {
    return StatsRow(name + " position (mm)", e.translation_m, 1000, "%.1f") +
           StatsRow(name + " rotation (°)", e.rotation_deg, 1, "%.3f");
  };
  h << "<h3>Trajectory</h3>\n<p class=\"note\">ATE after aligning the first "
       "pose; RPE over "
    << delta << " frames.</p>\n<table>" << kStatsHeader
    << traj_rows("ATE refined", report.ate_refined)
    << traj_rows("ATE odometry", report.ate_odometry)
    << traj_rows("RPE refined", report.rpe_refined)
    << traj_rows("RPE odometry", report.rpe_odometry) << "</table>\n";
  {
    Bounds b;
    std::vector<Eigen::Vector2d> gt_xy, odo_xy, ref_xy;
    for (const auto& p : groundtruth) {
      gt_xy.emplace_back(p.world_from_cam.translation.head<2>());
    }
    for (const auto& p : odometry_aligned) {
      odo_xy.emplace_back(p.world_from_cam.translation.head<2>());
    }
    for (const auto& p : refined_aligned) {
      ref_xy.emplace_back(p.world_from_cam.translation.head<2>());
    }
    for (const auto* v : {&gt_xy, &odo_xy, &ref_xy}) {
      for (const auto& p : *v) b.Add(p.x(), p.y());
    }
    // Equal scales unless the path is nearly straight: then the drift
    // (centimetres) would be invisible across metres of travel.
    const double aspect = (b.x1 - b.x0) / std::max(1e-9, b.y1 - b.y0);
    const bool equal = aspect < 3.0 && aspect > 1.0 / 3.0;
    SvgPlot traj(b, 660, 360, equal, "x (m)", "y (m)");
    traj.Line(gt_xy, "#000", 2.5);
    traj.Line(odo_xy, "#d62728", 1.5, "5,3");
    traj.Line(ref_xy, "#1f77b4", 1.5);
    if (!gt_xy.empty()) traj.Marker(gt_xy.front(), "#000", "start");
    traj.Legend({{"#000", "ground truth"},
                 {"#d62728", "odometry"},
                 {"#1f77b4", "refined"}});

    const auto err_odo = PerFramePositionError(odometry_aligned, groundtruth);
    const auto err_ref = PerFramePositionError(refined_aligned, groundtruth);
    Bounds eb;
    eb.Add(0, 0);
    for (const auto* v : {&err_odo, &err_ref}) {
      for (const auto& p : *v) eb.Add(p.x(), p.y() * 100);
    }
    std::vector<Eigen::Vector2d> odo_cm, ref_cm;
    for (const auto& p : err_odo) odo_cm.emplace_back(p.x(), p.y() * 100);
    for (const auto& p : err_ref) ref_cm.emplace_back(p.x(), p.y() * 100);
    SvgPlot err(eb, 660, 300, false, "frame", "position error (cm)");
    err.Line(odo_cm, "#d62728", 1.5, "5,3");
    err.Line(ref_cm, "#1f77b4", 1.5);
    err.Legend({{"#d62728", "odometry"}, {"#1f77b4", "refined"}});
    h << "<div class=\"row\"><figure>" << traj.Finish()
      << "<figcaption>Camera path, top view (first pose aligned"
      << (equal ? "" : "; axes scaled differently") << ").</figcaption>"
      << "</figure><figure>" << err.Finish()
      << "<figcaption>Position error per frame.</figcaption></figure></div>\n";
  }

  // (f) Localization.
  if (!report.localization.runs.empty()) {
    h << LocalizationSection(report.localization, options.localization);
  }

  // (g) Timing.
  report.report_seconds = report_timer.ElapsedSeconds();
  h << "<h2 "
       "id=\"timing\">Timing</h2>\n<table><tr><th>stage</th><th>seconds</th></"
       "tr>\n"
    << "<tr><td>simulate</td><td>" << Fmt("%.2f", report.simulate_seconds)
    << "</td></tr>\n";
  const nlohmann::json& timings = report.mapping["timings_seconds"];
  for (const StageTiming& s : result.report.timings) {
    const double sec =
        timings.contains(s.name) ? timings[s.name].get<double>() : s.seconds;
    h << "<tr><td>&nbsp;&nbsp;map: " << HtmlEscape(s.name) << "</td><td>"
      << Fmt("%.2f", sec) << "</td></tr>\n";
  }
  h << "<tr><td>map (total, with writing)</td><td>"
    << Fmt("%.2f", report.mapping_seconds) << "</td></tr>\n"
    << "<tr><td>evaluation</td><td>" << Fmt("%.2f", report.evaluation_seconds)
    << "</td></tr>\n";
  if (!report.localization.runs.empty()) {
    const DemoLocalization& loc = report.localization;
    h << "<tr><td>localization: simulate the traversal</td><td>"
      << Fmt("%.2f", loc.simulate_seconds) << "</td></tr>\n";
    for (const DemoLocalizationRun& run : loc.runs) {
      h << "<tr><td>&nbsp;&nbsp;localization: " << run.name << " ("
        << run.report.frames << " updates)</td><td>"
        << Fmt("%.2f", run.report.seconds) << "</td></tr>\n";
    }
  }
  h << "<tr><td>report figures</td><td>" << Fmt("%.2f", report.report_seconds)
    << "</td></tr>\n"
    << "<tr><td><b>total</b></td><td><b>"
    << Fmt("%.2f", total_timer.ElapsedSeconds())
    << "</b></td></tr>\n</table>\n";
  h << "<p class=\"note\">All figures: <code>report.json</code>.</p>\n"
    << kCheckScript << "</body></html>\n";

  report.total_seconds = total_timer.ElapsedSeconds();
  WriteFileAtomic(report.report_json, report.ToJson().dump(2) + "\n");
  WriteFileAtomic(report.report_html, h.str());
  return report;
}

}  // namespace monomap
