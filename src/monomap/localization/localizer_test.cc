#include "monomap/localization/localizer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "monomap/sim/test_scene.h"
#include "monomap/util/error.h"

namespace monomap {
namespace {

constexpr double kDeg = M_PI / 180.0;

// Composes a planar motion (forward, left, turn) given in the base frame.
Pose2d Compose(const Pose2d& a, double fwd, double left, double turn) {
  return {a.x + fwd * std::cos(a.yaw) - left * std::sin(a.yaw),
          a.y + fwd * std::sin(a.yaw) + left * std::cos(a.yaw),
          WrapAngle(a.yaw + turn)};
}

// A robot drive: ground truth and drifting odometry (5 % scale error on
// translation and 10 % on rotation, plus noise).
struct Drive {
  std::vector<Pose2d> truth, odometry;
};

Drive MakeDrive(const Pose2d& start, int steps, double step_m,
                double turn_rad, uint64_t seed) {
  Drive d;
  Rng rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  d.truth.push_back(start);
  d.odometry.push_back({0, 0, 0});  // odometry has its own origin
  for (int i = 1; i < steps; ++i) {
    d.truth.push_back(Compose(d.truth.back(), step_m, 0, turn_rad));
    const double dyaw = turn_rad * 1.1 + 0.002 * n(rng);
    const double dy = 0.002 * n(rng);
    const double dx = step_m * (1.05 + 0.02 * n(rng));
    d.odometry.push_back(Compose(d.odometry.back(), dx, dy, dyaw));
  }
  return d;
}

class LocalizerTest : public ::testing::Test {
 public:
  LocalizerTest()
      : map_(testing::RoomMap()),
        camera_(testing::LiveCamera()),
        mount_(testing::BaseFromCam()),
        renderer_(map_) {}

  // Runs the filter over the drive; returns the per-step translation
  // errors of the camera estimate.
  std::vector<double> Run(const Drive& drive, Localizer* loc,
                          std::vector<LocalizerStepStats>* stats = nullptr) {
    std::vector<double> errors;
    for (size_t i = 0; i < drive.truth.size(); ++i) {
      const Rigid3d truth = WorldFromCamOfBase(drive.truth[i], mount_);
      const cv::Mat raw = testing::LiveImage(
          renderer_, camera_, truth, 0.85 + 0.1 * std::sin(i * 0.7), 10, 2.0,
          100 + i);
      OdometryIncrement odo;
      if (i > 0) {
        odo.base_prev = drive.odometry[i - 1];
        odo.base_cur = drive.odometry[i];
        odo.cam_prev_from_cam_cur =
            WorldFromCamOfBase(drive.odometry[i - 1], mount_).Inverse() *
            WorldFromCamOfBase(drive.odometry[i], mount_);
      }
      const LocalizerEstimate e = loc->Step(raw, odo);
      errors.push_back((e.world_from_cam.translation - truth.translation)
                           .norm());
      if (stats) stats->push_back(e.stats);
    }
    return errors;
  }

  const Map& map() const { return map_; }
  const Camera& camera() const { return camera_; }
  const Rigid3d& mount() const { return mount_; }

  Map map_;
  Camera camera_;
  Rigid3d mount_;
  Renderer renderer_;
};

double Max(const std::vector<double>& v) {
  return *std::max_element(v.begin(), v.end());
}

TEST_F(LocalizerTest, PlanarMclTracksFromAPose) {
  LocalizerOptions o;
  o.method = LocalizationMethod::kMcl;
  o.state = LocalizationState::kPlanar;
  o.mcl.num_particles = 500;
  o.mcl.kld.max_particles = 500;
  o.init.spread_m = 0.05;
  o.recovery.injection_fraction = 0.0;
  o.seed = 3;
  Localizer loc(map_, camera_, o, mount_);
  const Drive drive = MakeDrive({0.0, 0.0, 0.1}, 30, 0.03, 1.0 * kDeg, 1);
  loc.InitializeAtPose(WorldFromCamOfBase(drive.truth[0], mount_));
  std::vector<LocalizerStepStats> stats;
  const std::vector<double> e = Run(drive, &loc, &stats);
  double sum = 0;
  for (double x : e) sum += x;
  std::printf("MCL planar tracking: mean %.1f mm, max %.1f mm, last %.1f mm, "
              "particles %d\n",
              1e3 * sum / e.size(), 1e3 * Max(e), 1e3 * e.back(),
              stats.back().particles);
  EXPECT_LT(Max(std::vector<double>(e.begin() + 3, e.end())), 0.02);
  EXPECT_LT(sum / e.size(), 0.012);
}

TEST_F(LocalizerTest, PlanarMccTracksFromAPose) {
  LocalizerOptions o;
  o.method = LocalizationMethod::kMcc;
  o.state = LocalizationState::kPlanar;
  o.mcl.num_particles = 300;
  o.mcl.kld.max_particles = 300;
  o.init.spread_m = 0.05;
  o.seed = 4;
  Localizer loc(map_, camera_, o, mount_);
  const Drive drive = MakeDrive({0.2, -0.3, -0.4}, 30, 0.03, 1.5 * kDeg, 2);
  loc.InitializeAtPose(WorldFromCamOfBase(drive.truth[0], mount_));
  std::vector<LocalizerStepStats> stats;
  const std::vector<double> e = Run(drive, &loc, &stats);
  int accepted = 0;
  for (const auto& s : stats) accepted += s.mcc_accepted;
  double sum = 0;
  for (double x : e) sum += x;
  std::printf("MCC planar tracking: mean %.1f mm, max %.1f mm, last %.1f mm, "
              "mcc accepted %d, particles %d\n",
              1e3 * sum / e.size(), 1e3 * Max(e), 1e3 * e.back(), accepted,
              stats.back().particles);
  EXPECT_LT(Max(e), 0.02);
  EXPECT_LT(sum / e.size(), 0.005);
  EXPECT_GT(accepted, 30);
}

TEST_F(LocalizerTest, SixDofMccTracksFromAPose) {
  LocalizerOptions o;
  o.method = LocalizationMethod::kMcc;
  o.state = LocalizationState::k6Dof;
  o.mcl.num_particles = 300;
  o.mcl.kld.max_particles = 300;
  o.init.spread_m = 0.03;
  o.init.spread_deg = 2.0;
  o.seed = 5;
  Localizer loc(map_, camera_, o);
  const Drive drive = MakeDrive({0.5, 0.5, 2.0}, 25, 0.03, -1.0 * kDeg, 3);
  loc.InitializeAtPose(WorldFromCamOfBase(drive.truth[0], mount_));
  const std::vector<double> e = Run(drive, &loc);
  std::printf("MCC 6dof tracking: max %.1f mm, last %.1f mm\n", 1e3 * Max(e),
              1e3 * e.back());
  EXPECT_LT(Max(std::vector<double>(e.begin() + 2, e.end())), 0.02);
  EXPECT_LT(e.back(), 0.01);
}

TEST_F(LocalizerTest, SixDofMccEstimateRefinementReducesError) {
  // The same drive and seed with and without the large-render refinement
  // of the estimate: the particles evolve identically (the refinement
  // changes only the output), the output gets closer to the truth.
  const Drive drive = MakeDrive({0.5, 0.5, 2.0}, 25, 0.03, -1.0 * kDeg, 3);
  double mean[2] = {0, 0};
  int refined = 0;
  for (int with = 0; with < 2; ++with) {
    LocalizerOptions o;
    o.method = LocalizationMethod::kMcc;
    o.state = LocalizationState::k6Dof;
    o.mcl.num_particles = 300;
    o.mcl.kld.max_particles = 300;
    o.init.spread_m = 0.03;
    o.init.spread_deg = 2.0;
    o.seed = 5;
    o.mcc.refine_estimate = with == 1;
    Localizer loc(map_, camera_, o);
    loc.InitializeAtPose(WorldFromCamOfBase(drive.truth[0], mount_));
    std::vector<LocalizerStepStats> stats;
    const std::vector<double> e = Run(drive, &loc, &stats);
    for (size_t i = 2; i < e.size(); ++i) mean[with] += e[i] / (e.size() - 2);
    if (with == 1) {
      for (const auto& s : stats) refined += s.refined ? 1 : 0;
    }
  }
  std::printf("MCC 6dof mean error: %.2f mm without, %.2f mm with estimate "
              "refinement (%d of %zu refined)\n",
              1e3 * mean[0], 1e3 * mean[1], refined, drive.truth.size());
  EXPECT_GE(refined, 20);
  EXPECT_LT(mean[1], 0.9 * mean[0]);  // measured 0.43 vs 0.54 mm
}

// Planar-state options with the KLD range [min_particles, particles] and
// random particles drawn over a 1 x 1 m area of the room, yaw unknown.
LocalizerOptions PlanarOverUnitArea(LocalizationMethod method, int particles,
                                    int min_particles) {
  LocalizerOptions o;
  o.method = method;
  o.state = LocalizationState::kPlanar;
  o.mcl.num_particles = particles;
  o.mcl.kld.max_particles = particles;
  o.mcl.kld.min_particles = min_particles;
  o.init.area_min = {0.0, -0.5};
  o.init.area_max = {1.0, 0.5};
  return o;
}

void GlobalInitCase(LocalizerTest* t, LocalizationMethod method,
                    std::vector<double>* e,
                    std::vector<LocalizerStepStats>* stats) {
  LocalizerOptions o = PlanarOverUnitArea(method, 3000, 200);
  o.init.kind = LocalizationInit::kGlobal;
  o.mcc.top_k = 10;
  o.seed = 6;
  Localizer loc(t->map(), t->camera(), o, t->mount());
  loc.Initialize(std::nullopt);
  // The initial set covers the area and all headings.
  double sx = 0, sxx = 0, sc = 0, ss = 0;
  for (const Particle& p : loc.particles()) {
    sx += p.base.x;
    sxx += p.base.x * p.base.x;
    sc += std::cos(p.base.yaw);
    ss += std::sin(p.base.yaw);
  }
  const double n = loc.particles().size();
  EXPECT_NEAR(std::sqrt(sxx / n - (sx / n) * (sx / n)), 1.0 / std::sqrt(12.0),
              0.02);
  EXPECT_LT(std::hypot(sc, ss) / n, 0.05);  // headings uniform
  const Drive drive = MakeDrive({0.4, 0.1, 0.5}, 15, 0.03, 2.0 * kDeg, 4);
  *e = t->Run(drive, &loc, stats);
  std::printf("global init: errors (m)");
  for (double x : *e) std::printf(" %.3f", x);
  std::printf("\nparticles");
  for (const auto& s : *stats) std::printf(" %d", s.particles);
  std::printf("\n");
}

TEST_F(LocalizerTest, PlanarGlobalInitConvergesWithMcl) {
  std::vector<double> e;
  std::vector<LocalizerStepStats> stats;
  GlobalInitCase(this, LocalizationMethod::kMcl, &e, &stats);
  EXPECT_LT(e.back(), 0.025);
  EXPECT_LT(Max(std::vector<double>(e.begin() + 10, e.end())), 0.03);
  // KLD shrinks the set once the filter has converged.
  EXPECT_LT(stats.back().particles, 1000);
  EXPECT_EQ(stats.front().particles_weighed, 3000);
}

TEST_F(LocalizerTest, PlanarGlobalInitConvergesWithMcc) {
  std::vector<double> e;
  std::vector<LocalizerStepStats> stats;
  GlobalInitCase(this, LocalizationMethod::kMcc, &e, &stats);
  EXPECT_LT(Max(std::vector<double>(e.begin() + 3, e.end())), 0.005);
  // After convergence, corrected duplicates merge into a handful.
  EXPECT_LT(stats.back().particles, 50);
  EXPECT_GT(stats.back().merged, 100);
}

// Kidnapped robot: the filter starts sure of a pose 0.4 m and 90 degrees
// from the truth. Without injection MCC stays lost (1.5 m off at the end);
// with the default 4 random particles per resampling, each corrected, one
// finds the truth (measured: at update 15 of 40, then < 1 mm).
TEST_F(LocalizerTest, MccRecoversFromAKidnappingByInjection) {
  const Drive drive = MakeDrive({0.4, 0.1, 0.5}, 40, 0.02, 1.0 * kDeg, 7);
  auto run = [&](int min_injected) {
    LocalizerOptions o =
        PlanarOverUnitArea(LocalizationMethod::kMcc, 200, 50);
    o.init.spread_m = 0.01;
    o.init.spread_deg = 1.0;
    o.recovery.injection_fraction = 0.0;
    o.recovery.mcc_min_injected = min_injected;
    // Injection alone (see the test below).
    o.recovery.relocalize_ncc_drop = 0.0;
    o.seed = 2;
    Localizer loc(map(), camera(), o, mount());
    loc.InitializeAtPose(WorldFromCamOfBase(
        Compose(drive.truth[0], 0.0, 0.4, 90.0 * kDeg), mount()));
    return Run(drive, &loc);
  };
  const std::vector<double> stuck = run(0);
  const std::vector<double> recovered =
      run(LocalizerOptions().recovery.mcc_min_injected);
  std::printf("kidnapped: first %.3f m; last without injection %.3f m, with "
              "%.3f m\n",
              stuck.front(), stuck.back(), recovered.back());
  EXPECT_GT(stuck.front(), 0.3);
  EXPECT_GT(stuck.back(), 0.2);
  EXPECT_LT(recovered.back(), 0.01);
}

// Kidnapped while tracking: the filter holds the pose for 10 updates, then
// the robot is carried 0.4 m to the left and turned 90 degrees while the
// odometry goes on as if nothing happened. Without any random particles
// MCC stays with the old pose; the relocalization trigger notices the drop
// of the best likelihood and injects 10 % of the budget per resampling
// until an injected particle, corrected, finds the truth. It must stay
// quiet while the filter tracks, before the jump and after recovering.
TEST_F(LocalizerTest, RelocalizationRecoversFromAKidnappingWhileTracking) {
  constexpr int kJump = 10;
  Drive drive = MakeDrive({0.3, 0.1, 0.3}, 45, 0.02, 1.0 * kDeg, 9);
  // The same motion after the jump: the truth is moved by a world-frame
  // transform, which leaves its increments (the odometry's) unchanged.
  const Pose2d t = drive.truth[kJump];
  const Pose2d t_inv = {-(std::cos(t.yaw) * t.x + std::sin(t.yaw) * t.y),
                        std::sin(t.yaw) * t.x - std::cos(t.yaw) * t.y, -t.yaw};
  const auto mul = [](const Pose2d& a, const Pose2d& b) {
    return Compose(a, b.x, b.y, b.yaw);
  };
  const Pose2d move = mul(Compose(t, 0.0, 0.4, 90.0 * kDeg), t_inv);
  for (size_t i = kJump; i < drive.truth.size(); ++i) {
    drive.truth[i] = mul(move, drive.truth[i]);
  }
  auto run = [&](double drop, std::vector<LocalizerStepStats>* stats) {
    LocalizerOptions o = PlanarOverUnitArea(LocalizationMethod::kMcc, 200, 50);
    o.init.spread_m = 0.01;
    o.init.spread_deg = 1.0;
    o.recovery.injection_fraction = 0.0;
    o.recovery.mcc_min_injected = 0;
    o.recovery.relocalize_ncc_drop = drop;
    o.seed = 3;
    Localizer loc(map(), camera(), o, mount());
    loc.InitializeAtPose(WorldFromCamOfBase(drive.truth[0], mount()));
    return Run(drive, &loc, stats);
  };
  std::vector<LocalizerStepStats> off_stats, on_stats;
  const std::vector<double> stuck = run(0.0, &off_stats);
  const std::vector<double> recovered =
      run(LocalizerOptions().recovery.relocalize_ncc_drop, &on_stats);
  std::string fired;
  for (const LocalizerStepStats& s : on_stats)
    fired += s.relocalizing ? '1' : '0';
  std::printf(
      "kidnapped while tracking: before the jump %.3f m; last "
      "without relocalization %.3f m, with %.3f m; relocalizing "
      "%s\n",
      Max(std::vector<double>(stuck.begin(), stuck.begin() + kJump)),
      stuck.back(), recovered.back(), fired.c_str());
  EXPECT_LT(
      Max(std::vector<double>(recovered.begin(), recovered.begin() + kJump)),
      0.01);
  EXPECT_GT(stuck.back(), 0.2);
  EXPECT_LT(recovered.back(), 0.01);
  // Quiet before the jump and over the last 10 updates; fired after it.
  EXPECT_EQ(fired.find('1'), fired.find('1', kJump));
  EXPECT_EQ(fired.substr(fired.size() - 10), std::string(10, '0'));
  EXPECT_GT(std::count(fired.begin(), fired.end(), '1'), 0);
  for (const LocalizerStepStats& s : off_stats) EXPECT_FALSE(s.relocalizing);
}

// The room's map cut at x = 1.2 m (the far wall and everything beyond
// dropped): the world the camera sees is still the whole room.
Map PartialRoomMap(const Map& room) {
  Map map = room;
  constexpr double kCut = 1.2 - (-1.0);  // along x from the room's x0
  map.planes[0].polygon = {{0, 0}, {kCut, 0}, {kCut, 3.0}, {0, 3.0}};
  map.planes[3].polygon = {{0, 0}, {kCut, 0}, {kCut, 1.2}, {0, 1.2}};
  map.planes[4].polygon = {
      {4.0 - kCut, 0}, {4.0, 0}, {4.0, 1.2}, {4.0 - kCut, 1.2}};
  map.planes.erase(map.planes.begin() + 1);  // the far wall
  return map;
}

// Tracking towards the map's edge: the views hold less and less map (as
// on a robot that drives out of the mapped area) while the pose stays
// right (within 3 cm). The trigger must stay quiet; judged on every view
// (coverage threshold 0, no persistence) it fires as the map leaves the
// view.
TEST_F(LocalizerTest, RelocalizationStaysQuietAsTheMapLeavesTheView) {
  const Map partial = PartialRoomMap(map());
  // 26 updates: beyond them the map fills a tenth of the view and MCC
  // loses the pose for real.
  const Drive drive = MakeDrive({0.0, 0.1, 0.0}, 26, 0.02, 0.2 * kDeg, 11);
  auto run = [&](double min_coverage, int min_updates,
                 std::vector<LocalizerStepStats>* stats) {
    LocalizerOptions o = PlanarOverUnitArea(LocalizationMethod::kMcc, 200, 50);
    o.init.spread_m = 0.01;
    o.init.spread_deg = 1.0;
    o.recovery.relocalize_min_coverage = min_coverage;
    o.recovery.relocalize_min_updates = min_updates;
    o.seed = 4;
    Localizer loc(partial, camera(), o, mount());
    loc.InitializeAtPose(WorldFromCamOfBase(drive.truth[0], mount()));
    return Run(drive, &loc, stats);
  };
  std::vector<LocalizerStepStats> on, every;
  const std::vector<double> errors =
      run(RecoveryOptions().relocalize_min_coverage,
          RecoveryOptions().relocalize_min_updates, &on);
  run(0.0, 1, &every);
  std::string fired, fired_every, coverage;
  for (size_t i = 0; i < on.size(); ++i) {
    fired += on[i].relocalizing ? '1' : '0';
    fired_every += every[i].relocalizing ? '1' : '0';
    if (i % 5 == 0) {
      char buf[64];
      std::snprintf(buf, sizeof(buf), " %.2f (%.3f m)", on[i].best_coverage,
                    errors[i]);
      coverage += buf;
    }
  }
  std::printf(
      "coverage (error) every 5 updates:%s\nrelocalizing %s\njudging every "
      "view %s\nlast error %.4f m\n",
      coverage.c_str(), fired.c_str(), fired_every.c_str(), errors.back());
  EXPECT_LT(on.back().best_coverage, 0.2);
  EXPECT_GT(on.front().best_coverage, 0.35);
  EXPECT_LT(Max(errors), 0.03);
  EXPECT_EQ(std::count(fired.begin(), fired.end(), '1'), 0);
  EXPECT_GT(std::count(fired_every.begin(), fired_every.end(), '1'), 0);
}

TEST_F(LocalizerTest, SixDofGlobalInitKeepsHeightAndTilt) {
  LocalizerOptions o;
  o.state = LocalizationState::k6Dof;
  o.mcl.num_particles = 400;
  o.init.area_min = {-0.5, -1.0};
  o.init.area_max = {2.5, 1.0};
  Localizer loc(map_, camera_, o);
  // No map trajectory and no reference: height and tilt are unknown.
  EXPECT_THROW(loc.InitializeGlobal(), StageError);
  const Rigid3d ref = WorldFromCamOfBase({0.3, 0.1, 0.7}, mount_);
  loc.InitializeGlobal(ref);
  ASSERT_EQ(loc.particles().size(), 400u);
  const Eigen::Vector3d ref_axis = ref.rotation * Eigen::Vector3d::UnitZ();
  for (const Particle& p : loc.particles()) {
    EXPECT_NEAR(p.world_from_cam.translation.z(), ref.translation.z(), 1e-12);
    EXPECT_GE(p.world_from_cam.translation.x(), -0.5);
    EXPECT_LE(p.world_from_cam.translation.y(), 1.0);
    // Same pitch: the optical axis keeps its angle to the vertical.
    const Eigen::Vector3d axis =
        p.world_from_cam.rotation * Eigen::Vector3d::UnitZ();
    EXPECT_NEAR(axis.z(), ref_axis.z(), 1e-9);
  }
}

TEST(LocalizerOptions, CheckAndParse) {
  LocalizerOptions o;
  EXPECT_NO_THROW(o.Check());
  o.recovery.injection_fraction = 1.5;
  EXPECT_THROW(o.Check(), OptionsError);
  o = {};
  o.mcl.num_particles = 0;
  EXPECT_THROW(o.Check(), OptionsError);
  o = {};
  // The slow average must be slower.
  o.recovery.relocalize_alpha_slow = o.recovery.relocalize_alpha_fast;
  EXPECT_THROW(o.Check(), OptionsError);
  o = {};
  o.recovery.relocalize_ncc_drop = -1.0;
  EXPECT_THROW(o.Check(), OptionsError);
  // Each stage's options are checked.
  o = {};
  o.mcc.top_k = -1;
  EXPECT_THROW(o.Check(), OptionsError);
  o = {};
  o.mcc.refinement.width = 8;
  EXPECT_THROW(o.Check(), OptionsError);
  o = {};
  o.init.spread_deg = -1.0;
  EXPECT_THROW(o.Check(), OptionsError);
  o = {};
  o.mcl.cluster_radius_m = 0.0;
  EXPECT_THROW(o.Check(), OptionsError);
  EXPECT_EQ(ParseLocalizationMethod("mcc"), LocalizationMethod::kMcc);
  EXPECT_EQ(ParseLocalizationState("6dof"), LocalizationState::k6Dof);
  EXPECT_EQ(ParseLocalizationInit("global"), LocalizationInit::kGlobal);
  EXPECT_THROW(ParseLocalizationMethod("ekf"), OptionsError);
}

}  // namespace
}  // namespace monomap
