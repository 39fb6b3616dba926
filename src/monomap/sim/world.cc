#include "monomap/sim/world.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <opencv2/imgproc.hpp>

#include <tbb/parallel_for.h>

#include "monomap/geometry/polygon.h"
#include "monomap/util/error.h"

namespace monomap {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

// Paints a BGR float texture (0..255) of a plane in metric units.
class Painter {
 public:
  Painter(cv::Mat* img, double ppm, cv::RNG* rng)
      : img_(*img), ppm_(ppm), rng_(*rng) {}

  int Px(double metres) const {
    return static_cast<int>(std::lround(metres * ppm_));
  }
  cv::Rect RectM(double s0, double t0, double w, double h) const {
    const cv::Rect r(Px(s0), Px(t0), std::max(1, Px(w)), std::max(1, Px(h)));
    return r & cv::Rect(0, 0, img_.cols, img_.rows);
  }
  double U(double a, double b) { return rng_.uniform(a, b); }
  // Channels drawn last first: the order of the worlds' textures since
  // their first figures (util/random.h says why it is spelled out).
  cv::Scalar Colour(double lo, double hi) {
    const double red = U(lo, hi), green = U(lo, hi), blue = U(lo, hi);
    return cv::Scalar(blue, green, red);
  }
  // A pixel uniform in [0, width) x [0, height), y drawn first.
  cv::Point Pixel(int width, int height) {
    const int y = rng_.uniform(0, height);
    return cv::Point(rng_.uniform(0, width), y);
  }

  // Band-limited Gaussian noise with features about `cell_m` metres wide,
  // unit standard deviation (single channel float).
  cv::Mat Noise(cv::Size size, double cell_m) {
    const double cell = std::max(1.0, cell_m * ppm_);
    cv::Mat out;
    if (cell < 1.5) {
      out.create(size, CV_32F);
      rng_.fill(out, cv::RNG::NORMAL, 0.0, 1.0);
      return out;
    }
    const int sw = static_cast<int>(std::ceil(size.width / cell)) + 2;
    const int sh = static_cast<int>(std::ceil(size.height / cell)) + 2;
    cv::Mat small(sh, sw, CV_32F);
    rng_.fill(small, cv::RNG::NORMAL, 0.0, 1.0);
    cv::resize(small, out, size, 0, 0, cv::INTER_CUBIC);
    return out;
  }

  // Adds grey noise of amplitude `amp` (grey levels) to `roi`, summing
  // octaves from `coarse_m` down to `fine_m`.
  void AddNoise(cv::Rect roi, double amp, double coarse_m, double fine_m) {
    roi &= cv::Rect(0, 0, img_.cols, img_.rows);
    if (roi.empty()) return;
    cv::Mat acc = cv::Mat::zeros(roi.size(), CV_32F);
    coarse_m = std::max(coarse_m, fine_m);  // at least one octave
    double a = 1.0, total = 0.0;
    for (double cell = coarse_m; cell >= fine_m * 0.999; cell *= 0.5) {
      cv::scaleAdd(Noise(roi.size(), cell), a, acc, acc);
      total += a * a;
      a *= 0.7;
    }
    const float scale = static_cast<float>(amp / std::sqrt(total));
    // One pass adding the grey field to the three channels (cheaper than
    // building a 3-channel copy of a large field).
    for (int y = 0; y < roi.height; ++y) {
      const float* n = acc.ptr<float>(y);
      cv::Vec3f* px = img_.ptr<cv::Vec3f>(roi.y + y) + roi.x;
      for (int x = 0; x < roi.width; ++x) {
        const float v = scale * n[x];
        px[x][0] += v;
        px[x][1] += v;
        px[x][2] += v;
      }
    }
  }

  void Fill(cv::Rect roi, const cv::Scalar& c) {
    roi &= cv::Rect(0, 0, img_.cols, img_.rows);
    if (!roi.empty()) img_(roi).setTo(c);
  }

  // Random text-like marks in a metric box: lines of random strings.
  void Text(cv::Rect box, double letter_m, const cv::Scalar& colour,
            int lines) {
    static const char kChars[] =
        "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789";
    const double letter_px = std::max(3.0, letter_m * ppm_);
    const double scale = letter_px / 22.0;
    const int thick = std::max(1, static_cast<int>(letter_px / 8.0));
    for (int l = 0; l < lines; ++l) {
      std::string s;
      const int n = rng_.uniform(3, 14);
      for (int i = 0; i < n; ++i) {
        s += (rng_.uniform(0, 6) == 0) ? ' ' : kChars[rng_.uniform(0, 62)];
      }
      const int y = box.y + static_cast<int>((l + 1) * letter_px * 1.6);
      if (y > box.y + box.height) break;
      cv::putText(img_, s, {box.x + static_cast<int>(U(0, letter_px)), y},
                  cv::FONT_HERSHEY_SIMPLEX, scale, colour, thick,
                  cv::LINE_AA);
    }
  }

  // A high-texture poster: shapes, text and noise on a light background.
  void Poster(cv::Rect r) {
    Fill(r, Colour(200, 250));
    // Shapes are drawn into the poster's sub-image so they stay inside it.
    cv::Mat sub = img_(r);
    for (int i = 0; i < 25; ++i) {
      const cv::Point c = Pixel(r.width, r.height);
      const int a = std::max(2, static_cast<int>(U(0.02, 0.12) * ppm_));
      const int b = std::max(2, static_cast<int>(U(0.02, 0.12) * ppm_));
      const cv::Scalar col = Colour(0, 230);
      const int thick = rng_.uniform(0, 3) == 0 ? -1 : std::max(1, a / 8);
      if (rng_.uniform(0, 2) == 0) {
        cv::ellipse(sub, c, {a, b}, U(0, 180), 0, 360, col, thick,
                    cv::LINE_AA);
      } else {
        cv::rectangle(sub, {c.x - a, c.y - b}, {c.x + a, c.y + b}, col,
                      thick, cv::LINE_AA);
      }
    }
    cv::Rect text_box(r.x + r.width / 10, r.y + r.height * 6 / 10,
                      r.width * 8 / 10, r.height * 4 / 10);
    Text(text_box, 0.035, cv::Scalar(20, 20, 20), 5);
    // A dark frame.
    cv::rectangle(img_, r, cv::Scalar(40, 40, 40),
                  std::max(1, Px(0.01)));
    AddNoise(r, 8.0, 0.05, 1.0 / ppm_);
  }

  // A wooden door (with frame and handle) whose bottom is at `bottom_row`.
  void Door(double s0, double t_bottom, double width, double height) {
    const cv::Rect r = RectM(s0, t_bottom - height, width, height);
    if (r.empty()) return;
    const cv::Scalar base = Colour(60, 90) + cv::Scalar(0, 30, 60);
    const cv::Mat warp = Noise(r.size(), 0.3);
    const double period = U(0.006, 0.012) * ppm_;
    for (int y = 0; y < r.height; ++y) {
      for (int x = 0; x < r.width; ++x) {
        const double g =
            std::sin(2.0 * M_PI * x / period + 4.0 * warp.at<float>(y, x));
        auto& px = img_.at<cv::Vec3f>(r.y + y, r.x + x);
        for (int c = 0; c < 3; ++c) px[c] = base[c] * (1.0 + 0.18 * g);
      }
    }
    cv::rectangle(img_, r, cv::Scalar(35, 35, 40), std::max(1, Px(0.05)));
    const cv::Point handle(r.x + r.width - Px(0.12), r.y + Px(height - 1.0));
    cv::circle(img_, handle, std::max(2, Px(0.035)),
               cv::Scalar(170, 170, 175), -1, cv::LINE_AA);
    // A small sign on the door.
    const cv::Rect sign = RectM(s0 + width * 0.3, t_bottom - height + 0.3,
                                width * 0.4, 0.12);
    Fill(sign, cv::Scalar(230, 230, 230));
    Text(sign, 0.04, cv::Scalar(10, 10, 10), 1);
    AddNoise(r, 4.0, 0.1, 1.0 / ppm_);
  }

  cv::RNG& rng() { return rng_; }
  double ppm() const { return ppm_; }
  cv::Mat& img() { return img_; }

 private:
  cv::Mat& img_;
  double ppm_;
  cv::RNG& rng_;
};

// Non-overlapping intervals of `len` on [lo, hi] (rejection sampling).
std::vector<double> PlaceIntervals(cv::RNG& rng, int count, double len,
                                   double lo, double hi, double gap,
                                   std::vector<std::pair<double, double>>* used) {
  std::vector<double> starts;
  for (int tries = 0; tries < 200 && static_cast<int>(starts.size()) < count;
       ++tries) {
    const double s = rng.uniform(lo, std::max(lo + 1e-6, hi - len));
    bool ok = s + len <= hi;
    for (const auto& [a, b] : *used) {
      if (s < b + gap && s + len > a - gap) ok = false;
    }
    if (!ok) continue;
    used->push_back({s, s + len});
    starts.push_back(s);
  }
  return starts;
}

struct WallDecor {
  int doors = 0;
  int posters = 0;
  // Intervals (s) kept free (e.g. behind a panel standing off the wall).
  std::vector<std::pair<double, double>> keep_free;
};

void PaintWall(TexturedPlane* plane, double width, double height,
               const WallDecor& decor, cv::RNG* rng) {
  cv::Mat img(plane->texture.size(), CV_32FC3);
  Painter p(&img, plane->pixels_per_meter, rng);
  // Painted plaster: mostly low texture, the hard part for trackers.
  const double shade = p.U(190, 225);
  const double green_off = p.U(0, 10), blue_off = p.U(0, 20);
  img.setTo(cv::Scalar(shade - blue_off, shade - green_off, shade));
  p.AddNoise({0, 0, img.cols, img.rows}, 5.0, 0.8, 0.1);
  p.AddNoise({0, 0, img.cols, img.rows}, 2.0, 0.02, 1.0 / p.ppm());
  // Skirting board.
  p.Fill(p.RectM(0, height - 0.1, width, 0.1), p.Colour(60, 110));
  p.AddNoise(p.RectM(0, height - 0.1, width, 0.1), 5.0, 0.05, 0.01);
  std::vector<std::pair<double, double>> used = decor.keep_free;
  for (double s : PlaceIntervals(*rng, decor.doors, 0.9, 0.3, width - 0.3,
                                 0.4, &used)) {
    p.Door(s, height, 0.9, std::min(2.05, height - 0.2));
  }
  for (double s : PlaceIntervals(*rng, decor.posters, 0.6, 0.2, width - 0.2,
                                 0.3, &used)) {
    const double h = p.U(0.5, 0.9);
    const double top = height - p.U(1.9, 2.1);
    p.Poster(p.RectM(s, std::max(0.05, top), 0.6, h));
  }
  // A few small notices and switches.
  for (int i = 0; i < 4; ++i) {
    const double s = p.U(0.1, width - 0.3), z = p.U(0.9, 1.5);
    const double rh = p.U(0.08, 0.25), rw = p.U(0.06, 0.2);
    const cv::Rect r = p.RectM(s, height - z, rw, rh);
    bool free = true;
    for (const auto& [a, b] : used) {
      if (s < b + 0.05 && s + 0.25 > a - 0.05) free = false;
    }
    if (!free) continue;
    p.Fill(r, p.Colour(150, 250));
    p.Text(r, 0.02, cv::Scalar(30, 30, 30), 3);
  }
  cv::Mat bgr;
  img.convertTo(bgr, CV_8UC3);
  cv::cvtColor(bgr, plane->texture, cv::COLOR_BGR2BGRA);
}

// Floor tiles (hallway) or wooden planks (room): strong regular edges plus
// per-tile variation, so no two tiles look alike.
void PaintFloor(TexturedPlane* plane, double width, double height, bool planks,
                cv::RNG* rng) {
  cv::Mat img(plane->texture.size(), CV_32FC3);
  Painter p(&img, plane->pixels_per_meter, rng);
  img.setTo(cv::Scalar(25, 40, 55));  // gaps between planks
  if (planks) {
    const double pw = 0.15;
    for (double t = 0; t < height; t += pw) {
      double s = -p.U(0.0, 1.0);
      while (s < width) {
        const double len = p.U(0.6, 1.4);
        const cv::Rect r = p.RectM(std::max(0.0, s), t,
                                   std::min(len, len + s), pw);
        const cv::Scalar c = cv::Scalar(40, 80, 120) + p.Colour(-15, 25);
        p.Fill(r, c);
        if (!r.empty()) {
          const cv::Mat warp = p.Noise(r.size(), 0.2);
          const double period = p.U(0.004, 0.01) * p.ppm();
          for (int y = 0; y < r.height; ++y) {
            for (int x = 0; x < r.width; ++x) {
              const double g = std::sin(2 * M_PI * y / period +
                                        5.0 * warp.at<float>(y, x));
              img.at<cv::Vec3f>(r.y + y, r.x + x) *= 1.0 + 0.12 * g;
            }
          }
          cv::rectangle(img, r, cv::Scalar(25, 40, 55), 1);
        }
        s += len;
      }
    }
    p.AddNoise({0, 0, img.cols, img.rows}, 5.0, 0.05, 1.0 / p.ppm());
  } else {
    const double tile = 0.5;
    for (double t = 0; t < height; t += tile) {
      for (double s = 0; s < width; s += tile) {
        const double g = p.U(120, 165);
        const double green_off = p.U(0, 10), blue_off = p.U(0, 15);
        p.Fill(p.RectM(s, t, tile, tile),
               cv::Scalar(g - blue_off, g - green_off, g));
      }
    }
    // Terrazzo speckle: fine, high-contrast corners everywhere.
    p.AddNoise({0, 0, img.cols, img.rows}, 14.0, 0.03, 1.0 / p.ppm());
    for (double t = 0; t <= height + 1e-9; t += tile) {
      p.Fill(p.RectM(0, t - 0.004, width, 0.008), cv::Scalar(60, 60, 60));
    }
    for (double s = 0; s <= width + 1e-9; s += tile) {
      p.Fill(p.RectM(s - 0.004, 0, 0.008, height), cv::Scalar(60, 60, 60));
    }
    // Scuffs.
    for (int i = 0; i < static_cast<int>(width * height); ++i) {
      const cv::Point c = p.Pixel(img.cols, img.rows);
      const cv::Scalar colour = p.Colour(50, 90);
      const double angle = p.U(0, 180);
      const int a = p.Px(p.U(0.02, 0.1)), b = p.Px(p.U(0.005, 0.02));
      cv::ellipse(img, c, {a, b}, angle, 0, 360, colour, -1, cv::LINE_AA);
    }
  }
  cv::Mat bgr;
  img.convertTo(bgr, CV_8UC3);
  cv::cvtColor(bgr, plane->texture, cv::COLOR_BGR2BGRA);
}

// Acoustic ceiling tiles on a T-bar grid with bright light panels at the
// `lights` (given in plane coordinates).
void PaintCeiling(TexturedPlane* plane, const std::vector<Vector2d>& lights,
                  cv::RNG* rng) {
  cv::Mat img(plane->texture.size(), CV_32FC3);
  Painter p(&img, plane->pixels_per_meter, rng);
  img.setTo(cv::Scalar(215, 218, 220));
  p.AddNoise({0, 0, img.cols, img.rows}, 6.0, 0.02, 1.0 / p.ppm());
  const double tile = 0.6;
  const double w = img.cols / p.ppm(), h = img.rows / p.ppm();
  for (double t = 0; t <= h; t += tile) {
    p.Fill(p.RectM(0, t - 0.01, w, 0.02), cv::Scalar(170, 170, 170));
  }
  for (double s = 0; s <= w; s += tile) {
    p.Fill(p.RectM(s - 0.01, 0, 0.02, h), cv::Scalar(170, 170, 170));
  }
  for (const Vector2d& l : lights) {
    p.Fill(p.RectM(l.x() - 0.3, l.y() - 0.3, 0.6, 0.6),
           cv::Scalar(252, 252, 252));
  }
  cv::Mat bgr;
  img.convertTo(bgr, CV_8UC3);
  cv::cvtColor(bgr, plane->texture, cv::COLOR_BGR2BGRA);
}

// A whiteboard: aluminium frame, white surface with handwriting.
void PaintWhiteboard(TexturedPlane* plane, cv::RNG* rng) {
  cv::Mat img(plane->texture.size(), CV_32FC3);
  Painter p(&img, plane->pixels_per_meter, rng);
  img.setTo(cv::Scalar(238, 240, 240));
  p.AddNoise({0, 0, img.cols, img.rows}, 2.0, 0.3, 0.05);
  const cv::Scalar inks[] = {{150, 40, 20}, {20, 20, 20}, {30, 30, 170},
                             {40, 120, 30}};
  for (int i = 0; i < 8; ++i) {
    const cv::Point corner = p.Pixel(img.cols * 2 / 3, img.rows * 3 / 4);
    const cv::Rect box(corner.x, corner.y, img.cols / 3, img.rows / 4);
    p.Text(box, p.U(0.03, 0.06), inks[i % 4], 3);
  }
  for (int i = 0; i < 6; ++i) {
    std::vector<cv::Point> pts;
    cv::Point c = p.Pixel(img.cols, img.rows);
    for (int k = 0; k < 6; ++k) {
      pts.push_back(c);
      const int dy = p.Px(p.U(-0.1, 0.1));
      c += cv::Point(p.Px(p.U(-0.15, 0.15)), dy);
    }
    cv::polylines(img, pts, false, inks[i % 4], std::max(1, p.Px(0.005)),
                  cv::LINE_AA);
  }
  cv::rectangle(img, {0, 0, img.cols, img.rows}, cv::Scalar(160, 165, 170),
                std::max(2, p.Px(0.03)));
  cv::Mat bgr;
  img.convertTo(bgr, CV_8UC3);
  cv::cvtColor(bgr, plane->texture, cv::COLOR_BGR2BGRA);
}

// Cardboard (with tape, labels and barcodes) or grey sheet metal.
void PaintBoxFace(TexturedPlane* plane, bool metal, cv::RNG* rng) {
  cv::Mat img(plane->texture.size(), CV_32FC3);
  Painter p(&img, plane->pixels_per_meter, rng);
  const double w = img.cols / p.ppm(), h = img.rows / p.ppm();
  if (metal) {
    img.setTo(cv::Scalar(150, 150, 145) + p.Colour(-10, 10));
    p.AddNoise({0, 0, img.cols, img.rows}, 3.0, 0.2, 0.02);
    for (double t = 0.3; t < h; t += 0.45) {
      p.Fill(p.RectM(0.02, t, w - 0.04, 0.008), cv::Scalar(90, 90, 90));
      p.Fill(p.RectM(w * 0.45, t + 0.1, w * 0.1, 0.025),
             cv::Scalar(60, 60, 60));
    }
    const cv::Rect label = p.RectM(w * 0.2, 0.1, w * 0.6, 0.12);
    p.Fill(label, cv::Scalar(240, 240, 235));
    p.Text(label, 0.03, cv::Scalar(20, 20, 20), 2);
  } else {
    img.setTo(cv::Scalar(70, 130, 175) + p.Colour(-15, 15));
    p.AddNoise({0, 0, img.cols, img.rows}, 7.0, 0.1, 1.0 / p.ppm());
    p.Fill(p.RectM(w * 0.42, 0, w * 0.16, h), cv::Scalar(110, 170, 200));
    const double label_t = h * p.U(0.1, 0.4);
    const cv::Rect label =
        p.RectM(w * p.U(0.05, 0.3), label_t, w * 0.35, h * 0.35);
    p.Fill(label, cv::Scalar(245, 245, 245));
    p.Text(label, 0.025, cv::Scalar(15, 15, 15), 3);
    // Barcode.
    int x = label.x + label.width / 10;
    const int y1 = label.y + label.height * 6 / 10;
    const int y2 = label.y + label.height * 9 / 10;
    while (x < label.x + label.width * 9 / 10) {
      const int bw = std::max(1, p.rng().uniform(1, 4) * p.Px(0.002));
      if (p.rng().uniform(0, 2)) {
        cv::rectangle(img, {x, y1}, {x + bw - 1, y2}, cv::Scalar(0, 0, 0),
                      -1);
      }
      x += bw;
    }
    const int arrows = 2;
    for (int i = 0; i < arrows; ++i) {
      const int ay = p.Px(h * p.U(0.5, 0.9));
      const cv::Point a(p.Px(w * p.U(0.1, 0.9)), ay);
      cv::arrowedLine(img, a, a - cv::Point(0, p.Px(0.08)),
                      cv::Scalar(20, 20, 20), std::max(1, p.Px(0.008)));
    }
  }
  cv::Mat bgr;
  img.convertTo(bgr, CV_8UC3);
  cv::cvtColor(bgr, plane->texture, cv::COLOR_BGR2BGRA);
}

// A door leaf filling its whole texture (a recessed door is its own
// plane, behind the wall's opening).
void PaintDoorLeaf(TexturedPlane* plane, double width, double height,
                   cv::RNG* rng) {
  cv::Mat img(plane->texture.size(), CV_32FC3);
  Painter p(&img, plane->pixels_per_meter, rng);
  img.setTo(cv::Scalar(50, 50, 55));
  p.Door(0.0, height, width, height);
  cv::Mat bgr;
  img.convertTo(bgr, CV_8UC3);
  cv::cvtColor(bgr, plane->texture, cv::COLOR_BGR2BGRA);
}

// Painted wooden trim (door jambs and lintel soffits): one colour, fine
// grain.
void PaintTrim(TexturedPlane* plane, cv::RNG* rng) {
  cv::Mat img(plane->texture.size(), CV_32FC3);
  Painter p(&img, plane->pixels_per_meter, rng);
  img.setTo(p.Colour(150, 200));
  p.AddNoise({0, 0, img.cols, img.rows}, 6.0, 0.02, 1.0 / p.ppm());
  cv::Mat bgr;
  img.convertTo(bgr, CV_8UC3);
  cv::cvtColor(bgr, plane->texture, cv::COLOR_BGR2BGRA);
}

// Vertical rectangle from floor point a to b, z in [z0, z1], with its
// normal towards the left of a->b (the side it is seen from). Seen from
// there, u points right and v up, so the texture is not mirrored: its rows
// are painted top-down and flipped by WorldBuilder::Finish.
TexturedPlane VerticalRect(int id, const Vector2d& a, const Vector2d& b,
                           double z0, double z1, double ppm) {
  const Vector2d d = a - b;
  const Vector3d u(d.x() / d.norm(), d.y() / d.norm(), 0.0);
  return MakeRectanglePlane(id, Vector3d(b.x(), b.y(), z0), u,
                            Vector3d::UnitZ(), d.norm(), z1 - z0, ppm);
}

// Horizontal rectangle [x0,x1]x[y0,y1] at height z, facing up or down.
TexturedPlane HorizontalRect(int id, double x0, double x1, double y0,
                             double y1, double z, bool up, double ppm) {
  if (up) {
    return MakeRectanglePlane(id, Vector3d(x0, y0, z), Vector3d::UnitX(),
                              Vector3d::UnitY(), x1 - x0, y1 - y0, ppm);
  }
  return MakeRectanglePlane(id, Vector3d(x0, y1, z), Vector3d::UnitX(),
                            -Vector3d::UnitY(), x1 - x0, y1 - y0, ppm);
}

// Adds planes with their geometry at once and defers the painting, so
// Finish() can paint all textures in parallel (each plane has its own
// seeded generator: the result does not depend on the threads).
class WorldBuilder {
 public:
  WorldBuilder(World* world, uint64_t seed, double ppm)
      : world_(*world), seed_(seed), ppm_(ppm) {}

  void Wall(const Vector2d& a, const Vector2d& b, double h,
            const WallDecor& decor) {
    const double width = (b - a).norm();
    Add(VerticalRect(NextId(), a, b, 0.0, h, ppm_),
        [width, h, decor](TexturedPlane* p, cv::RNG* rng) {
          PaintWall(p, width, h, decor, rng);
        });
  }
  void Floor(double x0, double x1, double y0, double y1, bool planks) {
    world_.floor_plane = NextId();
    Add(HorizontalRect(NextId(), x0, x1, y0, y1, 0.0, true, ppm_),
        [=](TexturedPlane* p, cv::RNG* rng) {
          PaintFloor(p, x1 - x0, y1 - y0, planks, rng);
        });
  }
  void Ceiling(double x0, double x1, double y0, double y1, double z) {
    TexturedPlane plane =
        HorizontalRect(NextId(), x0, x1, y0, y1, z, false, ppm_);
    std::vector<Vector2d> lights_st;
    for (const Vector3d& l : world_.lights) {
      lights_st.push_back(plane.frame.ToPlane(Vector3d(l.x(), l.y(), z)));
    }
    Add(std::move(plane), [lights_st](TexturedPlane* p, cv::RNG* rng) {
      PaintCeiling(p, lights_st, rng);
    });
  }
  // Axis-aligned box standing on the floor: top and four sides, normals
  // outwards (sides traversed clockwise seen from above).
  void Box(double x0, double x1, double y0, double y1, double h, bool metal) {
    const Vector2d c[4] = {{x0, y0}, {x0, y1}, {x1, y1}, {x1, y0}};
    auto paint = [metal](TexturedPlane* p, cv::RNG* rng) {
      PaintBoxFace(p, metal, rng);
    };
    for (int i = 0; i < 4; ++i) {
      Add(VerticalRect(NextId(), c[i], c[(i + 1) % 4], 0.0, h, ppm_), paint);
    }
    Add(HorizontalRect(NextId(), x0, x1, y0, y1, h, true, ppm_), paint);
  }
  // A wall from a to b with doors recessed `depth` behind it: the wall's
  // polygon has a notch at each opening (`door_s`: distances from b, in
  // the texture's s), and each door adds its leaf, two jambs and a soffit.
  void WallWithDoors(const Vector2d& a, const Vector2d& b, double h,
                     const std::vector<double>& door_s, int posters,
                     double door_w, double door_h, double depth) {
    const double width = (b - a).norm();
    TexturedPlane wall = VerticalRect(NextId(), a, b, 0.0, h, ppm_);
    WallDecor decor{0, posters, {}};
    wall.polygon = {{0.0, 0.0}};
    for (const double s0 : door_s) {
      wall.polygon.insert(wall.polygon.end(), {{s0, 0.0}, {s0, door_h},
                                               {s0 + door_w, door_h},
                                               {s0 + door_w, 0.0}});
      decor.keep_free.push_back({s0, s0 + door_w});
    }
    wall.polygon.insert(wall.polygon.end(), {{width, 0.0}, {width, h},
                                             {0.0, h}});
    Add(std::move(wall), [width, h, decor](TexturedPlane* p, cv::RNG* rng) {
      PaintWall(p, width, h, decor, rng);
    });
    const Vector2d u = (a - b).normalized();
    const Vector2d n(u.y(), -u.x());  // left of a -> b: the wall's normal
    for (const double s0 : door_s) {
      Door(b + s0 * u, b + (s0 + door_w) * u, -depth * n, door_h);
    }
  }
  // An axis-aligned floor or ceiling whose extent is `polygon` (x, y),
  // within the rectangle [x0, x1] x [y0, y1] of its texture.
  void FloorPolygon(double x0, double x1, double y0, double y1,
                    const std::vector<Vector2d>& polygon_xy) {
    world_.floor_plane = NextId();
    TexturedPlane plane = HorizontalRect(NextId(), x0, x1, y0, y1, 0.0, true,
                                         ppm_);
    SetPolygonXy(&plane, polygon_xy);
    Add(std::move(plane), [=](TexturedPlane* p, cv::RNG* rng) {
      PaintFloor(p, x1 - x0, y1 - y0, false, rng);
    });
  }
  void CeilingPolygon(double x0, double x1, double y0, double y1, double z,
                      const std::vector<Vector2d>& polygon_xy) {
    TexturedPlane plane =
        HorizontalRect(NextId(), x0, x1, y0, y1, z, false, ppm_);
    SetPolygonXy(&plane, polygon_xy);
    std::vector<Vector2d> lights_st;
    for (const Vector3d& l : world_.lights) {
      lights_st.push_back(plane.frame.ToPlane(Vector3d(l.x(), l.y(), z)));
    }
    Add(std::move(plane), [lights_st](TexturedPlane* p, cv::RNG* rng) {
      PaintCeiling(p, lights_st, rng);
    });
  }
  void Whiteboard(const Vector2d& a, const Vector2d& b, double z0,
                  double z1) {
    Add(VerticalRect(NextId(), a, b, z0, z1, ppm_),
        [](TexturedPlane* p, cv::RNG* rng) { PaintWhiteboard(p, rng); });
  }

  void Finish() {
    tbb::parallel_for(size_t{0}, jobs_.size(), [&](size_t i) {
      cv::RNG rng(SimMixSeed(seed_, i));
      jobs_[i](&world_.planes[i], &rng);
      // Painters draw row 0 at the top; texture row 0 is at t = 0, the
      // bottom of walls (v points up).
      cv::flip(world_.planes[i].texture, world_.planes[i].texture, 0);
    });
  }

 private:
  using Job = std::function<void(TexturedPlane*, cv::RNG*)>;
  int NextId() const { return static_cast<int>(world_.planes.size()); }
  // The opening p0 -> p1 (on the wall line) of a door recessed by
  // `behind` (a floor vector pointing away from the corridor): the leaf
  // faces the corridor like its wall, the jambs face the opening's
  // middle, the soffit faces down.
  void Door(const Vector2d& p0, const Vector2d& p1, const Vector2d& behind,
            double door_h) {
    const double door_w = (p1 - p0).norm();
    Add(VerticalRect(NextId(), p1 + behind, p0 + behind, 0.0, door_h, ppm_),
        [door_w, door_h](TexturedPlane* p, cv::RNG* rng) {
          PaintDoorLeaf(p, door_w, door_h, rng);
        });
    auto trim = [](TexturedPlane* p, cv::RNG* rng) { PaintTrim(p, rng); };
    const Vector2d along = (p1 - p0).normalized();
    Add(VerticalRectFacing(p0, p0 + behind, along, door_h), trim);
    Add(VerticalRectFacing(p1, p1 + behind, -along, door_h), trim);
    const Vector2d lo = p0.cwiseMin(p1).cwiseMin(p0 + behind);
    const Vector2d hi = p0.cwiseMax(p1).cwiseMax(p1 + behind);
    Add(HorizontalRect(NextId(), lo.x(), hi.x(), lo.y(), hi.y(), door_h,
                       false, ppm_),
        trim);
  }
  // A vertical rectangle between floor points p and q whose normal points
  // along `facing`.
  TexturedPlane VerticalRectFacing(const Vector2d& p, const Vector2d& q,
                                   const Vector2d& facing, double h) const {
    TexturedPlane r = VerticalRect(NextId(), p, q, 0.0, h, ppm_);
    if (r.plane.normal.head<2>().dot(facing) < 0) {
      r = VerticalRect(NextId(), q, p, 0.0, h, ppm_);
    }
    return r;
  }
  static void SetPolygonXy(TexturedPlane* plane,
                           const std::vector<Vector2d>& polygon_xy) {
    plane->polygon.clear();
    for (const Vector2d& xy : polygon_xy) {
      plane->polygon.push_back(
          plane->frame.ToPlane(Vector3d(xy.x(), xy.y(), plane->frame.origin.z())));
    }
    // Counter-clockwise in the plane's (s, t), whichever way it faces.
    if (PolygonArea(plane->polygon) < 0) {
      std::reverse(plane->polygon.begin(), plane->polygon.end());
    }
  }
  void Add(TexturedPlane plane, Job job) {
    world_.planes.push_back(std::move(plane));
    jobs_.push_back(std::move(job));
  }

  World& world_;
  uint64_t seed_;
  double ppm_;
  std::vector<Job> jobs_;
};

void BuildHallway(World* w, uint64_t seed, double ppm) {
  const double len = 10.0, half = 1.0, h = 2.5;
  for (double x = 1.25; x < len; x += 2.5) w->lights.push_back({x, 0.0, h});
  WorldBuilder b(w, seed, ppm);
  b.Wall({0, -half}, {len, -half}, h, {2, 3, {}});
  b.Wall({len, half}, {0, half}, h, {2, 3, {}});
  b.Wall({len, -half}, {len, half}, h, {0, 1, {}});
  b.Wall({0, half}, {0, -half}, h, {0, 1, {}});
  b.Floor(0, len, -half, half, false);
  b.Ceiling(0, len, -half, half, h);
  b.Finish();
  w->path_keypoints = {{0.8, 0.0},  {2.5, 0.25}, {4.5, -0.25},
                       {6.5, 0.2},  {8.3, -0.1}, {9.0, 0.0}};
  w->path_closed = false;
}

void BuildLabCorner(World* w, uint64_t seed, double ppm) {
  const double len = 6.0, h = 2.5;
  w->lights = {{2.0, 2.0, h}, {4.0, 3.0, h}};
  WorldBuilder b(w, seed, ppm);
  b.Wall({0, 0}, {len, 0}, h, {1, 2, {}});
  // The whiteboard stands off this wall over s = y in [1.4, 2.8].
  b.Wall({0, len}, {0, 0}, h, {0, 2, {{1.3, 2.9}}});
  b.Floor(0, len, 0, len, false);
  b.Whiteboard({0.35, 2.8}, {0.35, 1.4}, 0.8, 2.0);
  b.Box(3.0, 4.0, 0.05, 0.55, 0.9, true);
  b.Finish();
  w->path_keypoints = {{5.0, 3.6}, {3.6, 2.9}, {2.3, 2.2},
                       {1.9, 1.5}, {2.3, 1.0}, {3.6, 1.1}};
  w->path_closed = false;
}

void BuildRoom(World* w, uint64_t seed, double ppm) {
  const double sx = 5.0, sy = 4.0, h = 2.5;
  w->lights = {{1.7, 1.3, h}, {3.3, 2.7, h}};
  WorldBuilder b(w, seed, ppm);
  b.Wall({0, 0}, {sx, 0}, h, {1, 2, {}});
  b.Wall({sx, 0}, {sx, sy}, h, {0, 2, {}});
  b.Wall({sx, sy}, {0, sy}, h, {1, 1, {}});
  b.Wall({0, sy}, {0, 0}, h, {0, 2, {}});
  b.Floor(0, sx, 0, sy, true);
  b.Ceiling(0, sx, 0, sy, h);
  b.Box(1.2, 1.8, 2.7, 3.3, 0.6, false);
  b.Box(3.0, 3.8, 1.1, 1.6, 0.75, false);
  b.Box(4.3, 4.9, 3.2, 3.9, 1.8, true);
  b.Finish();
  w->path_keypoints = {{1.0, 1.0}, {2.5, 0.6}, {3.9, 0.6}, {4.45, 1.5},
                       {4.0, 2.6}, {2.6, 2.35}, {1.0, 2.2}};
  w->path_closed = true;
}

// An L-shaped office corridor, 2 m wide and 2.5 m high: 10 m along x, then
// a left turn into 6 m along y. Painted walls with plain stretches, a few
// posters and skirting boards; doors recessed 5 cm with jambs and soffits,
// placed by the seed. The robot drives down the middle and round the
// corner, so the long side walls are seen at grazing angles throughout.
void BuildOffice(World* w, uint64_t seed, double ppm) {
  const double h = 2.5, door_w = 0.9, door_h = 2.05, depth = 0.05;
  w->lights = {{1.25, 0, h}, {3.75, 0, h}, {6.25, 0, h},
               {9.0, 0, h},  {9.0, 2.5, h}, {9.0, 5.0, h}};
  cv::RNG rng(SimMixSeed(seed, 0xd00f));
  // Door positions (s from the wall's end point b), clear of the corners.
  auto doors = [&](int count, double len) {
    std::vector<std::pair<double, double>> used;
    std::vector<double> s =
        PlaceIntervals(rng, count, door_w, 0.6, len - 0.6, 0.8, &used);
    std::sort(s.begin(), s.end());
    return s;
  };
  WorldBuilder b(w, seed, ppm);
  // The boundary counter-clockwise, so the corridor is left of each wall.
  b.WallWithDoors({0, -1}, {10, -1}, h, doors(2, 10.0), 3, door_w, door_h,
                  depth);
  b.WallWithDoors({10, -1}, {10, 7}, h, doors(2, 8.0), 2, door_w, door_h,
                  depth);
  b.Wall({10, 7}, {8, 7}, h, {0, 1, {}});
  b.WallWithDoors({8, 7}, {8, 1}, h, doors(1, 6.0), 1, door_w, door_h,
                  depth);
  b.WallWithDoors({8, 1}, {0, 1}, h, doors(2, 8.0), 2, door_w, door_h,
                  depth);
  b.Wall({0, 1}, {0, -1}, h, {0, 1, {}});
  const std::vector<Vector2d> outline = {{0, -1}, {10, -1}, {10, 7},
                                         {8, 7},  {8, 1},   {0, 1}};
  b.FloorPolygon(0, 10, -1, 7, outline);
  b.CeilingPolygon(0, 10, -1, 7, h, outline);
  b.Finish();
  w->path_keypoints = {{0.8, 0.0}, {3.0, 0.1}, {5.5, -0.1}, {7.6, 0.0},
                       {8.7, 0.5}, {9.0, 1.8}, {9.0, 4.0},  {9.0, 6.2}};
  w->path_closed = false;
}

}  // namespace

uint64_t SimMixSeed(uint64_t a, uint64_t b) {
  uint64_t z = a + 0x9e3779b97f4a7c15ULL * (b + 1);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

size_t World::TextureBytes() const {
  size_t bytes = 0;
  for (const TexturedPlane& p : planes) {
    bytes += p.texture.total() * p.texture.elemSize();
  }
  return bytes;
}

std::vector<std::string> WorldNames() {
  return {"hallway", "lab-corner", "room", "office"};
}

TexturedPlane MakeRectanglePlane(int id, const Vector3d& origin,
                                 const Vector3d& u_axis, const Vector3d& v_axis,
                                 double width, double height,
                                 double pixels_per_meter) {
  TexturedPlane p;
  p.id = id;
  p.frame.origin = origin;
  p.frame.u_axis = u_axis.normalized();
  p.frame.v_axis = v_axis.normalized();
  p.plane.normal = p.frame.u_axis.cross(p.frame.v_axis).normalized();
  p.plane.offset = -p.plane.normal.dot(origin);
  p.pixels_per_meter = pixels_per_meter;
  p.polygon = {{0.0, 0.0}, {width, 0.0}, {width, height}, {0.0, height}};
  const int cols = static_cast<int>(std::ceil(width * pixels_per_meter));
  const int rows = static_cast<int>(std::ceil(height * pixels_per_meter));
  p.texture.create(rows, cols, CV_8UC4);
  p.texture.setTo(cv::Scalar(0, 0, 0, 255));
  return p;
}

World MakeWorld(const std::string& name, uint64_t seed,
                double pixels_per_meter) {
  CheckOption(pixels_per_meter >= 20 && pixels_per_meter <= 2000,
              "world.pixels_per_meter", "must be in [20, 2000]");
  World w;
  w.name = name;
  if (name == "hallway") {
    BuildHallway(&w, seed, pixels_per_meter);
  } else if (name == "lab-corner") {
    BuildLabCorner(&w, seed, pixels_per_meter);
  } else if (name == "room") {
    BuildRoom(&w, seed, pixels_per_meter);
  } else if (name == "office") {
    BuildOffice(&w, seed, pixels_per_meter);
  } else {
    std::string valid;
    for (const std::string& n : WorldNames()) {
      valid += (valid.empty() ? "" : ", ") + n;
    }
    throw OptionsError("world '" + name + "' is unknown (valid: " + valid +
                       ")");
  }
  return w;
}

}  // namespace monomap
