#include "monomap/triangulation/point_trust.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "monomap/sim/test_scene.h"
#include "monomap/triangulation/triangulator.h"
#include "monomap/util/error.h"
#include "monomap/util/random.h"

namespace monomap {
namespace {

constexpr int kClean = 200;
constexpr int kShort = 6;  // two observations
constexpr int kJumps = 5;  // jump 15 px half way: large residual
constexpr int kTiny = 7;   // 8 frames, 21 mm baseline at 2.5 m: ~0.5 deg

// Landmarks triangulated (with every acceptance test off) from a noisy
// simulated scene plus planted bad tracks: the quality the filter judges is
// the one triangulation measured. Ids >= kClean are the planted ones.
std::vector<Landmark> LandmarksWithPlantedBadPoints(double noise_px = 0.3) {
  testing::TestSceneOptions scene_options;
  scene_options.points.num_tracks = kClean;
  scene_options.points.pixel_noise_px = noise_px;
  scene_options.seed = 11;
  const testing::TestScene scene = testing::MakeTestScene(scene_options);
  std::vector<Track> tracks = scene.tracks;
  FeatureId next_id = kClean;
  for (int k = 0; k < kShort; ++k) {
    Track t = scene.tracks[k];
    t.id = next_id++;
    t.observations.resize(2);
    tracks.push_back(t);
  }
  for (int k = 0; k < kJumps; ++k) {
    Track t = scene.tracks[10 + k];
    t.id = next_id++;
    for (size_t i = t.observations.size() / 2; i < t.observations.size(); ++i) {
      t.observations[i].px += Eigen::Vector2d(0.0, -15.0);
    }
    tracks.push_back(t);
  }
  std::mt19937_64 rng(4);
  std::normal_distribution<double> noise(0.0, noise_px);
  for (int k = 0; k < kTiny; ++k) {
    const int frame = 3 * k;
    const Eigen::Vector3d x = scene.world_from_cam[frame + 4] *
                              Eigen::Vector3d(0.25 - 0.05 * k, 0.1, 2.5);
    Track t;
    t.id = next_id++;
    for (int f = frame; f < frame + 8; ++f) {
      t.observations.push_back(
          {f, scene.camera.ImageFromCam(scene.world_from_cam[f].Inverse() * x) +
                  DrawLastFirst<Eigen::Vector2d>(noise, rng)});
    }
    tracks.push_back(t);
  }
  TriangulationOptions accept_all;
  accept_all.min_track_length = 2;
  accept_all.max_reprojection_error_px = 1e6;
  accept_all.max_observation_error_px = 1e6;
  accept_all.min_triangulation_angle_deg = 0.0;
  std::vector<Landmark> landmarks;
  TriangulateTracks(scene.camera, scene.world_from_cam, tracks, accept_all,
                    &landmarks);
  return landmarks;
}

TEST(PointTrustTest, LeavesOutThePlantedBadPointsAndKeepsTheGoodOnes) {
  const std::vector<Landmark> all = LandmarksWithPlantedBadPoints();
  ASSERT_EQ(all.size(), static_cast<size_t>(kClean + kShort + kJumps + kTiny));
  // The planted points really carry the bad quality.
  for (const Landmark& l : all) {
    if (l.id >= kClean + kShort && l.id < kClean + kShort + kJumps) {
      EXPECT_GT(l.mean_reprojection_error_px, 4.0) << l.id;
    } else if (l.id >= kClean + kShort + kJumps) {
      EXPECT_LT(l.triangulation_angle_deg, 1.0) << l.id;
      EXPECT_LT(l.mean_reprojection_error_px, 1.0) << l.id;
    }
  }
  std::vector<Landmark> kept = all;
  PointTrustOptions options;
  options.max_relative_uncertainty = 0.0;  // its own test below
  const PointTrustReport report = FilterTrustedPoints(options, &kept);
  EXPECT_EQ(report.num_points, static_cast<int>(all.size()));
  EXPECT_EQ(report.num_exported, kClean);
  EXPECT_EQ(report.short_track, kShort);
  EXPECT_EQ(report.reprojection_error, kJumps);
  EXPECT_EQ(report.triangulation_angle, kTiny);
  EXPECT_FALSE(report.keep_all);
  ASSERT_EQ(kept.size(), static_cast<size_t>(kClean));
  for (int i = 0; i < kClean; ++i) {
    EXPECT_EQ(kept[i].id, i);  // the clean ones, in order
    EXPECT_EQ(kept[i].x_in_world, all[i].x_in_world);
  }
}

TEST(PointTrustTest, KeepAllExportsEveryPointAndCountsTheUntrusted) {
  const std::vector<Landmark> all = LandmarksWithPlantedBadPoints();
  std::vector<Landmark> kept = all;
  PointTrustOptions options;
  options.keep_all = true;
  options.max_relative_uncertainty = 0.0;
  const PointTrustReport report = FilterTrustedPoints(options, &kept);
  EXPECT_TRUE(report.keep_all);
  EXPECT_EQ(report.num_exported, static_cast<int>(all.size()));
  EXPECT_EQ(report.short_track, kShort);
  EXPECT_EQ(report.reprojection_error, kJumps);
  EXPECT_EQ(report.triangulation_angle, kTiny);
  ASSERT_EQ(kept.size(), all.size());
  for (size_t i = 0; i < all.size(); ++i) EXPECT_EQ(kept[i].id, all[i].id);
}

// Each threshold counts exactly the points beyond it, and the first failing
// test claims a point.
TEST(PointTrustTest, ThresholdsCountExactlyThePointsBeyondThem) {
  const std::vector<Landmark> all = LandmarksWithPlantedBadPoints();
  PointTrustOptions options;
  options.min_track_length = 12;
  options.max_mean_reprojection_error_px = 0.4;
  options.max_reprojection_error_median_ratio = 0.0;  // the absolute limit
  options.min_triangulation_angle_deg = 6.0;
  options.max_relative_uncertainty = 0.0;
  int short_track = 0, error = 0, angle = 0;
  for (const Landmark& l : all) {
    if (l.num_observations < 12) {
      ++short_track;
    } else if (l.mean_reprojection_error_px > 0.4) {
      ++error;
    } else if (l.triangulation_angle_deg < 6.0) {
      ++angle;
    }
  }
  // The scene spans all three cases, so each test is exercised.
  EXPECT_GT(short_track, kShort + kTiny);
  EXPECT_GT(error, kJumps);
  EXPECT_GT(angle, 0);
  std::vector<Landmark> kept = all;
  const PointTrustReport report = FilterTrustedPoints(options, &kept);
  EXPECT_EQ(report.short_track, short_track);
  EXPECT_EQ(report.reprojection_error, error);
  EXPECT_EQ(report.triangulation_angle, angle);
  EXPECT_EQ(report.num_exported,
            static_cast<int>(all.size()) - short_track - error - angle);
  ASSERT_EQ(kept.size(), static_cast<size_t>(report.num_exported));
  for (const Landmark& l : kept) {
    EXPECT_GE(l.num_observations, 12);
    EXPECT_LE(l.mean_reprojection_error_px, 0.4);
    EXPECT_GE(l.triangulation_angle_deg, 6.0);
  }
  // A NaN quality is never trusted.
  std::vector<Landmark> nan_point(1, all[0]);
  nan_point[0].mean_reprojection_error_px = std::nan("");
  EXPECT_EQ(
      FilterTrustedPoints(PointTrustOptions{}, &nan_point).reprojection_error,
      1);
  EXPECT_TRUE(nan_point.empty());
}

// A limit relative to the map's median reprojection error fits any
// camera's noise: at 0.3 and at 1.2 px of tracking noise, twice the median
// keeps most clean points and leaves out the tracks that jumped, where one
// absolute limit (right for the first) leaves out most clean points of the
// second. The limit applied is reported.
TEST(PointTrustTest, AMedianRatioLimitFitsTheCamerasNoise) {
  for (const double noise_px : {0.3, 1.2}) {
    SCOPED_TRACE(noise_px);
    const std::vector<Landmark> all = LandmarksWithPlantedBadPoints(noise_px);
    PointTrustOptions relative;
    relative.min_track_length = 2;
    relative.min_triangulation_angle_deg = 0.0;
    relative.max_relative_uncertainty = 0.0;
    relative.max_mean_reprojection_error_px = 100.0;
    relative.max_reprojection_error_median_ratio = 2.0;
    PointTrustOptions absolute = relative;
    absolute.max_reprojection_error_median_ratio = 0.0;
    absolute.max_mean_reprojection_error_px = 0.6;
    for (const bool use_ratio : {true, false}) {
      std::vector<Landmark> kept = all;
      const PointTrustReport report =
          FilterTrustedPoints(use_ratio ? relative : absolute, &kept);
      int clean = 0;
      for (const Landmark& l : kept) {
        EXPECT_FALSE(l.id >= kClean + kShort && l.id < kClean + kShort + kJumps)
            << "a track that jumped is kept";
        clean += l.id < kClean;
      }
      if (use_ratio) {
        EXPECT_GT(clean, 0.9 * kClean);
        EXPECT_GT(report.reprojection_limit_px, noise_px);
        EXPECT_LT(report.reprojection_limit_px, 4.0 * noise_px);
      } else if (noise_px > 1.0) {
        EXPECT_LT(clean, 0.5 * kClean);
      }
    }
  }
}

// The points the uncertainty test leaves out are the ones that are really
// off: of the clean simulated points (0.3 px noise), those whose predicted
// sigma exceeds 2 % of their depth have larger true errors (relative to
// depth) than those kept.
TEST(PointTrustTest, UncertainPointsAreTheOnesThatAreOff) {
  testing::TestSceneOptions scene_options;
  scene_options.points.num_tracks = kClean;
  scene_options.points.pixel_noise_px = 0.3;
  scene_options.seed = 11;
  const testing::TestScene scene = testing::MakeTestScene(scene_options);
  const std::vector<Landmark> all = LandmarksWithPlantedBadPoints();
  PointTrustOptions options;
  options.min_track_length = 2;
  options.max_mean_reprojection_error_px = 1e6;
  options.min_triangulation_angle_deg = 0.0;
  std::vector<Landmark> kept(all.begin(), all.begin() + kClean);
  const PointTrustReport report = FilterTrustedPoints(options, &kept);
  EXPECT_GT(report.uncertainty, 10);  // the scene has loose points
  EXPECT_GT(report.num_exported, kClean / 2);
  std::vector<double> kept_error, dropped_error;
  std::vector<bool> is_kept(kClean, false);
  for (const Landmark& l : kept) is_kept[l.id] = true;
  for (int i = 0; i < kClean; ++i) {
    const double e =
        (all[i].x_in_world - scene.points[i]).norm() / all[i].mean_depth_m;
    (is_kept[i] ? kept_error : dropped_error).push_back(e);
  }
  auto median = [](std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  };
  EXPECT_GT(median(dropped_error), 3.0 * median(kept_error));
  // No covariance: trusted; a NaN depth: not; the bound off: all kept.
  std::vector<Landmark> special(3, all[0]);
  special[0].covariance_m2_per_px2.setZero();
  special[0].mean_depth_m = 1.0;
  special[1].mean_depth_m = std::nan("");
  special[2].covariance_m2_per_px2 = Eigen::Matrix3d::Identity();  // 1 m
  std::vector<Landmark> out = special;
  EXPECT_EQ(FilterTrustedPoints(options, &out).uncertainty, 2);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_TRUE(out[0].covariance_m2_per_px2.isZero());
  options.max_relative_uncertainty = 0.0;
  out = special;
  EXPECT_EQ(FilterTrustedPoints(options, &out).num_exported, 3);
}

TEST(PointTrustTest, CheckRejectsBadValues) {
  EXPECT_NO_THROW(PointTrustOptions{}.Check());
  auto error_of = [](const PointTrustOptions& o) -> std::string {
    try {
      o.Check();
    } catch (const OptionsError& e) {
      return e.what();
    }
    return "";
  };
  PointTrustOptions o;
  o.min_track_length = 1;
  EXPECT_NE(error_of(o).find("min_track_length"), std::string::npos);
  o = {};
  o.max_mean_reprojection_error_px = 0.0;
  EXPECT_NE(error_of(o).find("max_mean_reprojection_error_px"),
            std::string::npos);
  o.max_mean_reprojection_error_px = std::nan("");
  EXPECT_NE(error_of(o).find("max_mean_reprojection_error_px"),
            std::string::npos);
  o = {};
  o.max_reprojection_error_median_ratio = -1.0;
  EXPECT_NE(error_of(o).find("max_reprojection_error_median_ratio"),
            std::string::npos);
  o = {};
  o.max_relative_uncertainty = std::nan("");
  EXPECT_NE(error_of(o).find("max_relative_uncertainty"), std::string::npos);
  o = {};
  o.min_triangulation_angle_deg = -0.5;
  EXPECT_NE(error_of(o).find("min_triangulation_angle_deg"), std::string::npos);
  o.min_triangulation_angle_deg = 180.0;
  EXPECT_NE(error_of(o).find("min_triangulation_angle_deg"), std::string::npos);
  // The filter checks its options before touching the points.
  std::vector<Landmark> points(3);
  EXPECT_THROW(FilterTrustedPoints(o, &points), OptionsError);
  EXPECT_EQ(points.size(), 3u);
}

}  // namespace
}  // namespace monomap
