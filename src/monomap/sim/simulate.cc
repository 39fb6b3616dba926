#include "monomap/sim/simulate.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <sstream>

#include "monomap/io/dataset.h"
#include "monomap/io/map_format.h"
#include "monomap/io/trajectory_io.h"
#include "monomap/util/angles.h"
#include "monomap/util/error.h"
#include "monomap/util/file.h"
#include "monomap/util/progress.h"

namespace monomap {
namespace fs = std::filesystem;

void SimulationOptions::Check() const {
  const auto names = WorldNames();
  if (std::find(names.begin(), names.end(), world) == names.end()) {
    MakeWorld(world, seed, 20.0);  // throws the error listing valid names
  }
  CheckOption(num_frames == -1 || num_frames > 0, "sim.num_frames",
              "must be -1 (whole path) or > 0");
  CheckOption(width >= 16 && height >= 16 && width <= 8192 && height <= 8192,
              "sim.width/height", "must be in [16, 8192]");
  CheckOption(focal_px_at_640 > 50 && focal_px_at_640 < 5000,
              "sim.focal_px_at_640", "must be in (50, 5000)");
  CheckOption(std::abs(k1) < 1.0 && std::abs(k2) < 1.0, "sim.k1/k2",
              "must be within +-1");
  CheckOption(LensModelFromName(lens).has_value(), "sim.lens",
              "must be plumb_bob or equidistant");
  CheckOption(
      texture_pixels_per_meter >= 20 && texture_pixels_per_meter <= 2000,
      "sim.texture_pixels_per_meter", "must be in [20, 2000]");
  path.Check();
  mount.Check();
  CheckOption(floor_tilt_deg >= 0 && floor_tilt_deg <= 10, "sim.floor_tilt_deg",
              "must be in [0, 10]");
  odometry.Check();
  render.Check();
  effects.Check();
  CheckOption(
      moving_object_start_fraction >= 0 && moving_object_start_fraction <= 1,
      "sim.moving_object_start_fraction", "must be in [0, 1]");
  CheckOption(moving_object_duration_fraction > 0 &&
                  moving_object_duration_fraction <= 1,
              "sim.moving_object_duration_fraction", "must be in (0, 1]");
  CheckOption(moving_object_radius_m > 0.01 && moving_object_radius_m < 2,
              "sim.moving_object_radius_m", "must be in (0.01, 2)");
  CheckOption(moving_object_distance_m > 0.2 && moving_object_distance_m < 20,
              "sim.moving_object_distance_m", "must be in (0.2, 20)");
  CheckOption(highlight_strength >= 0 && highlight_strength <= 255,
              "sim.highlight_strength", "must be in [0, 255]");
  CheckOption(highlight_radius_m > 0 && highlight_radius_m < 5,
              "sim.highlight_radius_m", "must be in (0, 5)");
}

Camera MakeSimulationCamera(const SimulationOptions& options) {
  // Same horizontal field of view at any width; square pixels; principal
  // point at the centre (pixel centres at integers).
  Camera c;
  c.width = options.width;
  c.height = options.height;
  c.fx = c.fy = options.focal_px_at_640 * options.width / 640.0;
  c.cx = (options.width - 1) * 0.5;
  c.cy = (options.height - 1) * 0.5;
  c.distortion = {options.k1, options.k2, 0.0, 0.0, 0.0};
  c.model = LensModelFromName(options.lens).value_or(LensModel::kPlumbBob);
  return c;
}

namespace {

std::string FormatOdometry2d(const std::vector<TimedPose2d>& poses) {
  std::ostringstream out;
  out << "# planar wheel odometry of the robot base: timestamp x y yaw\n";
  char buf[160];
  for (const TimedPose2d& p : poses) {
    std::snprintf(buf, sizeof(buf), "%.6f %.9f %.9f %.9f\n", p.timestamp,
                  p.pose.x, p.pose.y, p.pose.yaw);
    out << buf;
  }
  return out.str();
}

std::vector<TimedPose> CameraPoses(const std::vector<TimedPose2d>& base,
                                   const Rigid3d& base_from_cam) {
  std::vector<TimedPose> out;
  out.reserve(base.size());
  for (const TimedPose2d& p : base) {
    out.push_back({p.timestamp, WorldFromCamOfBase(p.pose, base_from_cam)});
  }
  return out;
}

// The true camera poses on an uneven floor: the base rolls and pitches
// about its origin by smooth functions of the distance driven.
std::vector<TimedPose> TiltedCameraPoses(const std::vector<TimedPose2d>& base,
                                         const Rigid3d& base_from_cam,
                                         double amplitude_deg, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> phase(0.0, 2.0 * M_PI);
  const double roll_phase[2] = {phase(rng), phase(rng)};
  const double pitch_phase[2] = {phase(rng), phase(rng)};
  auto wave = [&](const double* ph, double s) {
    return DegToRad(amplitude_deg) *
           (0.6 * std::sin(2.0 * M_PI * s / 1.3 + ph[0]) +
            0.4 * std::sin(2.0 * M_PI * s / 0.45 + ph[1]));
  };
  std::vector<TimedPose> out;
  double s = 0.0;
  for (size_t i = 0; i < base.size(); ++i) {
    const Pose2d& p = base[i].pose;
    if (i > 0) {
      s += std::hypot(p.x - base[i - 1].pose.x, p.y - base[i - 1].pose.y);
    }
    const Eigen::Quaterniond tilt = QuaternionFromRotationVector(
        Eigen::Vector3d(wave(roll_phase, s), wave(pitch_phase, s), 0));
    out.push_back(
        {base[i].timestamp,
         WorldFromCamOfBase(
             p, Rigid3d(tilt, Eigen::Vector3d::Zero()) * base_from_cam)});
  }
  return out;
}

// Frame count, structure size and the odometry's drift at the end.
void FillPathReport(const World& world, const std::vector<TimedPose2d>& truth,
                    const std::vector<TimedPose2d>& odom,
                    SimulationReport* report) {
  report->frames = static_cast<int>(truth.size());
  report->planes = static_cast<int>(world.planes.size());
  report->texture_megabytes = world.TextureBytes() / 1e6;
  report->path_length_m = PathLength(truth);
  const Pose2d& a = truth.back().pose;
  const Pose2d& b = odom.back().pose;
  report->final_drift_m = std::hypot(a.x - b.x, a.y - b.y);
  report->final_drift_percent =
      report->path_length_m > 0
          ? 100.0 * report->final_drift_m / report->path_length_m
          : 0.0;
  report->final_yaw_error_deg =
      RadToDegMulDiv(std::abs(std::remainder(a.yaw - b.yaw, 2.0 * M_PI)));
}

// Adds the (hidden) moving disc and its frame span to the report; returns
// its plane index.
int AddMovingObject(const SimulationOptions& options, int n,
                    SceneRenderer* renderer, SimulationReport* report) {
  const int object_index = renderer->AddPlane(MakeDiscObject(
      options.moving_object_radius_m, options.texture_pixels_per_meter,
      SimMixSeed(options.seed, 77)));
  renderer->SetPlaneVisible(object_index, false);
  report->moving_object_first_frame = std::min(
      n - 1, static_cast<int>(options.moving_object_start_fraction * n));
  report->moving_object_last_frame = std::min(
      n - 1, report->moving_object_first_frame +
                 std::max(0, static_cast<int>(
                                 options.moving_object_duration_fraction * n) -
                                 1));
  return object_index;
}

// Shows the moving disc in frame i (facing the camera, sweeping across the
// middle 70% of `half_width`) while it is present.
void PlaceMovingObject(const SimulationOptions& options,
                       const SimulationReport& report, int object_index, int i,
                       const Rigid3d& world_from_cam, double half_width,
                       SceneRenderer* renderer) {
  const int f0 = report.moving_object_first_frame;
  const int f1 = report.moving_object_last_frame;
  const bool present = i >= f0 && i <= f1;
  renderer->SetPlaneVisible(object_index, present);
  if (!present) return;
  const double u = f1 > f0 ? static_cast<double>(i - f0) / (f1 - f0) : 0.5;
  const Eigen::Vector3d centre_in_cam((2.0 * u - 1.0) * 0.7 * half_width, 0.05,
                                      options.moving_object_distance_m);
  const Eigen::Vector3d centre = world_from_cam * centre_in_cam;
  Plane plane;
  PlaneFrame frame;
  PlaceDisc(options.moving_object_radius_m, centre,
            world_from_cam.translation - centre, &plane, &frame);
  renderer->SetPlanePose(object_index, plane, frame);
}

// The lights' specular reflections on the floor seen from the camera.
std::vector<SceneRenderer::Highlight> FloorHighlights(
    const SimulationOptions& options, const World& world,
    const Rigid3d& world_from_cam) {
  std::vector<SceneRenderer::Highlight> highlights;
  if (!options.specular_highlight || world.floor_plane < 0) return highlights;
  for (const Eigen::Vector3d& light : world.lights) {
    SceneRenderer::Highlight h;
    if (!SpecularPoint(light, world_from_cam.translation, 0.0, &h.centre)) {
      continue;
    }
    h.plane_index = world.floor_plane;
    h.radius_m = options.highlight_radius_m;
    h.strength = options.highlight_strength;
    highlights.push_back(h);
  }
  return highlights;
}

// Writes camera.yaml, camera_mount.yaml and the odometry and ground truth
// files into the dataset directory `root`.
void WriteDatasetFiles(const fs::path& root, const Camera& camera,
                       const World& world, const Rigid3d& base_from_cam,
                       const std::vector<TimedPose2d>& odom,
                       const std::vector<TimedPose>& odom_cam,
                       const std::vector<TimedPose>& gt_cam) {
  WriteCameraYaml(root / "camera.yaml", camera, "monomap_sim_" + world.name);
  WriteCameraMountYaml(root / "camera_mount.yaml", base_from_cam);
  WriteFileAtomic(root / "odometry2d.txt", FormatOdometry2d(odom));
  WriteTumTrajectory(root / "odometry.txt", odom_cam,
                     "simulated wheel odometry composed with the mount");
  WriteTumTrajectory(root / "groundtruth.txt", gt_cam,
                     "simulated ground truth (" + world.name + ")");
}

// Writes frame i's image as rgb/NNNNNN.png and appends its line to rgb.txt.
void WriteFrame(const fs::path& root, int i, double timestamp,
                const cv::Mat& image, std::ostringstream* rgb_list) {
  char name[32];
  std::snprintf(name, sizeof(name), "rgb/%06d.png", i);
  if (!cv::imwrite((root / name).string(), image)) {
    throw OutputError((root / name).string() + ": cannot write image");
  }
  char line[96];
  std::snprintf(line, sizeof(line), "%.6f %s\n", timestamp, name);
  *rgb_list << line;
}

// Renders every frame from its true pose into root/rgb and writes rgb.txt.
void RenderFrames(const SimulationOptions& options, const World& world,
                  const Camera& camera, const std::vector<TimedPose2d>& truth,
                  const std::vector<TimedPose>& gt_cam, uint64_t run_seed,
                  const SimulationReport& report, int object_index,
                  const fs::path& root, SceneRenderer* renderer) {
  const int n = static_cast<int>(truth.size());
  // Half the horizontal field of view at the object distance: the object
  // sweeps over the middle 70% of it (further out it would often hide
  // behind nearby walls).
  const double half_width =
      options.moving_object_distance_m * (camera.width * 0.5) / camera.fx;
  std::ostringstream rgb_list;
  rgb_list << "# timestamp filename (simulated " << world.name << ")\n";
  ProgressBar progress("simulate " + world.name, n, options.show_progress);
  for (int i = 0; i < n; ++i) {
    const Rigid3d& world_from_cam = gt_cam[i].world_from_cam;
    if (object_index >= 0) {
      PlaceMovingObject(options, report, object_index, i, world_from_cam,
                        half_width, renderer);
    }
    const cv::Mat radiance = renderer->Render(
        world_from_cam, FloorHighlights(options, world, world_from_cam));
    const cv::Mat image = ApplyCameraEffects(
        radiance, truth[i].timestamp - truth[0].timestamp, options.effects,
        run_seed, SimMixSeed(run_seed, 1000000 + i));
    WriteFrame(root, i, truth[i].timestamp, image, &rgb_list);
    progress.Advance();
  }
  progress.Finish();
  WriteFileAtomic(root / "rgb.txt", rgb_list.str());
}

}  // namespace

SimulationReport Simulate(const SimulationOptions& options,
                          const fs::path& out_dir) {
  options.Check();
  Timer timer;
  SimulationReport report;
  report.world = options.world;

  const World world =
      MakeWorld(options.world, options.seed, options.texture_pixels_per_meter);
  const Camera camera = MakeSimulationCamera(options);
  const RobotPath path(world);
  const std::vector<TimedPose2d> truth =
      SampleRobotPath(path, options.path, options.num_frames);
  const uint64_t run_seed =
      options.run_seed != 0 ? options.run_seed : options.seed;
  const std::vector<TimedPose2d> odom =
      SimulateOdometry(truth, options.odometry, run_seed);
  const Rigid3d base_from_cam = MakeCameraMount(options.mount);
  const std::vector<TimedPose> gt_cam =
      options.floor_tilt_deg > 0
          ? TiltedCameraPoses(truth, base_from_cam, options.floor_tilt_deg,
                              SimMixSeed(run_seed, 2000000))
          : CameraPoses(truth, base_from_cam);
  const std::vector<TimedPose> odom_cam = CameraPoses(odom, base_from_cam);
  FillPathReport(world, truth, odom, &report);
  const int n = report.frames;

  SceneRenderer renderer(camera, options.render);
  for (const TexturedPlane& p : world.planes) renderer.AddPlane(p);
  const int object_index = options.moving_object
                               ? AddMovingObject(options, n, &renderer, &report)
                               : -1;

  AtomicDirectory dir(out_dir, "dataset");
  const fs::path root = dir.path();
  fs::create_directories(root / "rgb");
  WriteDatasetFiles(root, camera, world, base_from_cam, odom, odom_cam, gt_cam);

  RenderFrames(options, world, camera, truth, gt_cam, run_seed, report,
               object_index, root, &renderer);

  if (options.write_structure) {
    Map structure;
    structure.camera = camera;
    structure.planes = world.planes;
    structure.trajectory = gt_cam;
    fs::create_directories(root / "structure");
    WriteMap(root / "structure", structure);
  }
  dir.Commit();
  report.seconds = timer.ElapsedSeconds();
  return report;
}

}  // namespace monomap
