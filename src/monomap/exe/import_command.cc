// monomap import rosbag BAG|BAGDIR -o DATASET --image-topic T
//   --camera-info-topic T
//   (--odom-topic T | --odom-tf odom:base_link) [--base-frame F] ...
// monomap import euroc DIR -o DATASET, monomap import kitti SEQ -o DATASET
// monomap import video FILE -o DATASET --camera YAML --odometry FILE
// monomap import tum DIR -o DATASET (--preset fr1 | --intrinsics fx,fy,cx,cy)
//   [--odometry FILE | --odometry-scale-error S ... --odometry-seed N]
// Converts robot logs and standard datasets into monomap's dataset layout
// (docs/importing.md), so every other command reads them unchanged.
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "monomap/exe/commands.h"
#include "monomap/io/bag_import.h"
#include "monomap/io/standard_import.h"
#include "monomap/util/error.h"
#include "monomap/util/file.h"
#ifdef MONOMAP_HAVE_ROSBAG
#include "monomap/io/rosbag_import.h"
#endif
#ifdef MONOMAP_HAVE_ROSBAG2
#include "monomap/io/rosbag2_import.h"
#endif

namespace monomap {
namespace {

// A directory, a metadata.yaml or a .db3 is a ROS 2 bag; anything else is
// read as a ROS 1 bag.
RosbagImportReport ImportAnyBag(const std::filesystem::path& bag,
                                const std::filesystem::path& out,
                                const RosbagImportOptions& o) {
  const bool ros2 = std::filesystem::is_directory(bag) ||
                    bag.extension() == ".db3" ||
                    bag.filename() == "metadata.yaml";
  if (ros2) {
#ifdef MONOMAP_HAVE_ROSBAG2
    return ImportRosbag2(bag, out, o);
#else
    throw Error("import rosbag: " + bag.string() +
                " is a ROS 2 bag, and this monomap was built without ROS 2 bag "
                "support (install libsqlite3-dev libfastcdr-dev and rebuild)");
#endif
  }
#ifdef MONOMAP_HAVE_ROSBAG
  return ImportRosbag(bag, out, o);
#else
  throw Error(
      "import rosbag: " + bag.string() +
      " is a ROS 1 bag, and this monomap was built without ROS 1 bag support "
      "(install librosbag-dev libsensor-msgs-dev libnav-msgs-dev "
      "libtf2-msgs-dev libgeometry-msgs-dev and rebuild)");
#endif
}

void RegisterRosbagImport(CLI::App* import) {
  CLI::App* cmd = import->add_subcommand(
      "rosbag",
      "ROS 1 bag or ROS 2 bag (sqlite3): images, CameraInfo, Odometry or tf, "
      "mount from /tf_static");
  auto bag = std::make_shared<std::string>();
  auto out = std::make_shared<std::string>();
  auto quiet = std::make_shared<bool>(false);
  cmd->add_option("bag", *bag,
                  "ROS 1 .bag file, or ROS 2 bag directory (metadata.yaml + "
                  ".db3; or one .db3 file)")
      ->required();
  cmd->add_option("-o,--output", *out, "Dataset directory to write")
      ->required();
  auto o = std::make_shared<RosbagImportOptions>();
  cmd->add_option("--image-topic", o->image_topic,
                  "sensor_msgs/Image or CompressedImage topic")
      ->required();
  cmd->add_option("--camera-info-topic", o->camera_info_topic,
                  "sensor_msgs/CameraInfo topic")
      ->required();
  auto* odom =
      cmd->add_option("--odom-topic", o->odom_topic, "nav_msgs/Odometry topic");
  auto* odom_tf =
      cmd->add_option("--odom-tf", o->odom_tf,
                      "Odometry as tf PARENT:CHILD, e.g. odom:base_link");
  odom->excludes(odom_tf);
  cmd->add_option("--tf-topic", o->tf_topic, "Topic of dynamic transforms")
      ->capture_default_str();
  cmd->add_option("--tf-static-topic", o->tf_static_topic,
                  "Topic of static transforms (the camera mount)")
      ->capture_default_str();
  cmd->add_option("--base-frame", o->base_frame,
                  "Robot base frame (default: the odometry's child frame)");
  cmd->add_option("--camera-frame", o->camera_frame,
                  "Camera frame (default: the images' frame_id)");
  cmd->add_option("--camera-mount", o->camera_mount,
                  "camera_mount.yaml to use instead of /tf_static");
  cmd->add_option("--max-odometry-gap", o->max_odometry_gap,
                  "Drop images in odometry gaps longer than this (s)")
      ->capture_default_str();
  cmd->add_flag("-q,--quiet", *quiet, "No summary");
  cmd->callback([o, bag, out, quiet]() {
    if (o->odom_topic.empty() && o->odom_tf.empty()) {
      throw OptionsError("import rosbag: give --odom-topic or --odom-tf");
    }
    CheckOutputDirectory(*out, "dataset", {*bag});
    const RosbagImportReport r = ImportAnyBag(*bag, *out, *o);
    if (*quiet) return;
    std::fprintf(stderr,
                 "monomap: %s: %d of %d images imported (%s), %d dropped "
                 "outside the odometry [%.3f, %.3f] s, %d in odometry gaps; "
                 "%d odometry samples; mount from %s; %s -> %s\n",
                 bag->c_str(), r.frames_written, r.images_in_bag,
                 r.image_encoding.c_str(), r.dropped_outside_odometry,
                 r.odometry_start, r.odometry_end, r.dropped_in_gap,
                 r.odometry_samples, r.mount_source.c_str(),
                 r.planar ? "planar base (odometry2d.txt written)"
                          : "6-DoF odometry only",
                 out->c_str());
  });
}

// Odometry file or simulated odometry, and the pose gap: the same for
// every layout that comes with ground truth only.
void AddPosedImageOptions(CLI::App* cmd, std::filesystem::path* odometry,
                          OdometryFromGroundTruthOptions* sim,
                          double* max_pose_gap) {
  cmd->add_option("--odometry", *odometry,
                  "TUM trajectory of odometry (default: simulate it from "
                  "the ground truth)");
  cmd->add_option("--odometry-scale-error", sim->scale_error,
                  "Simulated odometry: systematic scale error (fraction)")
      ->capture_default_str();
  cmd->add_option("--odometry-translation-noise", sim->translation_noise,
                  "Simulated odometry: random translation error (fraction of "
                  "each step)")
      ->capture_default_str();
  cmd->add_option("--odometry-rotation-noise", sim->rotation_noise_deg_per_m,
                  "Simulated odometry: random rotation error (deg per metre)")
      ->capture_default_str();
  cmd->add_option("--odometry-seed", sim->seed,
                  "Simulated odometry: seed of the random errors")
      ->capture_default_str();
  cmd->add_option("--max-pose-gap", *max_pose_gap,
                  "Drop images in trajectory gaps longer than this (s)")
      ->capture_default_str();
}

void PrintImportReport(const std::string& in, const std::string& out,
                       const ImportReport& r) {
  std::fprintf(stderr,
               "monomap: %s: %d of %d images imported, %d without a pose "
               "dropped; odometry %s",
               in.c_str(), r.frames_written, r.images_listed, r.dropped,
               r.odometry_simulated ? "SIMULATED from ground truth"
                                    : "from the given file");
  if (r.odometry_simulated) {
    std::fprintf(stderr, " (final drift %.3f m over %.2f m)", r.final_drift_m,
                 r.path_length_m);
  }
  std::fprintf(stderr, " -> %s\n", out.c_str());
}

void RegisterTumImport(CLI::App* import) {
  CLI::App* cmd = import->add_subcommand(
      "tum", "TUM RGB-D sequence as distributed (rgb.txt, groundtruth.txt)");
  auto o = std::make_shared<TumImportOptions>();
  auto dir = std::make_shared<std::string>();
  auto out = std::make_shared<std::string>();
  auto quiet = std::make_shared<bool>(false);
  cmd->add_option("dir", *dir, "TUM sequence directory")->required();
  cmd->add_option("-o,--output", *out, "Dataset directory to write")
      ->required();
  auto* preset = cmd->add_option("--preset", o->preset,
                                 "Published TUM calibration: fr1, fr2, fr3");
  auto* intrinsics =
      cmd->add_option("--intrinsics", o->intrinsics,
                      "fx,fy,cx,cy[,k1,k2,p1,p2[,k3]] (pixels, plumb_bob)")
          ->delimiter(',');
  preset->excludes(intrinsics);
  AddPosedImageOptions(cmd, &o->odometry, &o->simulated, &o->max_pose_gap);
  cmd->add_flag("-q,--quiet", *quiet, "No summary");
  cmd->callback([o, dir, out, quiet]() {
    CheckOutputDirectory(*out, "dataset", {*dir});
    const ImportReport r = ImportTum(*dir, *out, *o);
    if (!*quiet) PrintImportReport(*dir, *out, r);
  });
}

void RegisterEurocImport(CLI::App* import) {
  CLI::App* cmd = import->add_subcommand(
      "euroc", "EuRoC MAV sequence, ASL layout (mav0/cam0, sensor.yaml)");
  auto o = std::make_shared<EurocImportOptions>();
  auto dir = std::make_shared<std::string>();
  auto out = std::make_shared<std::string>();
  auto quiet = std::make_shared<bool>(false);
  cmd->add_option("dir", *dir, "Sequence directory (holding mav0/)")
      ->required();
  cmd->add_option("-o,--output", *out, "Dataset directory to write")
      ->required();
  cmd->add_option("--camera", o->camera, "Camera folder under mav0/")
      ->capture_default_str();
  AddPosedImageOptions(cmd, &o->odometry, &o->simulated, &o->max_pose_gap);
  cmd->add_flag("-q,--quiet", *quiet, "No summary");
  cmd->callback([o, dir, out, quiet]() {
    CheckOutputDirectory(*out, "dataset", {*dir});
    const ImportReport r = ImportEuroc(*dir, *out, *o);
    if (!*quiet) PrintImportReport(*dir, *out, r);
  });
}

void RegisterKittiImport(CLI::App* import) {
  CLI::App* cmd = import->add_subcommand(
      "kitti", "KITTI odometry sequence (calib.txt, times.txt, poses)");
  auto o = std::make_shared<KittiImportOptions>();
  auto dir = std::make_shared<std::string>();
  auto out = std::make_shared<std::string>();
  auto quiet = std::make_shared<bool>(false);
  cmd->add_option("sequence", *dir, "Sequence directory, e.g. sequences/00")
      ->required();
  cmd->add_option("-o,--output", *out, "Dataset directory to write")
      ->required();
  cmd->add_option("--camera", o->camera, "Camera 0-3 (image_N, PN)")
      ->capture_default_str();
  cmd->add_option("--poses", o->poses,
                  "Ground-truth poses (default: SEQ/../../poses/NN.txt)");
  AddPosedImageOptions(cmd, &o->odometry, &o->simulated, &o->max_pose_gap);
  cmd->add_flag("-q,--quiet", *quiet, "No summary");
  cmd->callback([o, dir, out, quiet]() {
    CheckOutputDirectory(*out, "dataset", {*dir});
    const ImportReport r = ImportKitti(*dir, *out, *o);
    if (!*quiet) PrintImportReport(*dir, *out, r);
  });
}

void RegisterVideoImport(CLI::App* import) {
  CLI::App* cmd = import->add_subcommand(
      "video", "Video file (anything OpenCV reads) plus an odometry file");
  auto o = std::make_shared<VideoImportOptions>();
  auto video = std::make_shared<std::string>();
  auto out = std::make_shared<std::string>();
  auto quiet = std::make_shared<bool>(false);
  cmd->add_option("video", *video, "Video file")->required();
  cmd->add_option("-o,--output", *out, "Dataset directory to write")
      ->required();
  cmd->add_option("--camera", o->camera_yaml, "camera_info YAML")->required();
  cmd->add_option("--odometry", o->odometry,
                  "TUM trajectory of odometry (world_from_cam)")
      ->required();
  cmd->add_option("--groundtruth", o->groundtruth,
                  "TUM ground truth, kept for evaluation");
  cmd->add_option("--start-time", o->start_time,
                  "Time of the first frame on the odometry's clock (s)")
      ->capture_default_str();
  cmd->add_option("--max-pose-gap", o->max_pose_gap,
                  "Drop frames in odometry gaps longer than this (s)")
      ->capture_default_str();
  cmd->add_flag("-q,--quiet", *quiet, "No summary");
  cmd->callback([o, video, out, quiet]() {
    CheckOutputDirectory(*out, "dataset", {*video});
    const ImportReport r = ImportVideo(*video, *out, *o);
    if (!*quiet) PrintImportReport(*video, *out, r);
  });
}

}  // namespace

void RegisterImportCommand(CLI::App& app) {
  CLI::App* import = app.add_subcommand(
      "import", "Convert a robot log or a standard dataset into a dataset");
  import->require_subcommand(1);
  RegisterRosbagImport(import);
  RegisterTumImport(import);
  RegisterEurocImport(import);
  RegisterKittiImport(import);
  RegisterVideoImport(import);
}

}  // namespace monomap
