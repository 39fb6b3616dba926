// monomap calibrate DATASET -o CAMERA.yaml [--board 9x6] [--square 0.04]
//     [--first-frame F --frames N]
#include <cstdio>
#include <memory>
#include <string>

#include "monomap/camera/calibration.h"
#include "monomap/exe/commands.h"
#include "monomap/io/dataset.h"
#include "monomap/util/error.h"
#include "monomap/util/file.h"

namespace monomap {

void RegisterCalibrateCommand(CLI::App& app) {
  struct Args {
    std::string dataset, output, board;
    bool radial_only = false;
    int first_frame = 0, num_frames = -1;
    CalibrationOptions options;
  };
  auto a = std::make_shared<Args>();
  a->board = std::to_string(a->options.inner_corners_x) + "x" +
             std::to_string(a->options.inner_corners_y);
  CLI::App* cmd = app.add_subcommand(
      "calibrate",
      "Refit the camera calibration from the dataset's views of a flat "
      "checkerboard, starting from its camera.yaml");
  cmd->add_option("dataset", a->dataset, "Dataset directory")->required();
  cmd->add_option("-o,--output", a->output,
                  "Calibration to write (ROS camera_info YAML)")
      ->required();
  cmd->add_option("--board", a->board, "Inner corners of the board, COLSxROWS")
      ->capture_default_str();
  cmd->add_option("--square", a->options.square_m, "Square side (m)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--stride", a->options.stride, "Use every n-th frame")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_flag("--radial-only", a->radial_only,
                "Fit k1, k2 only (no p1, p2, k3)");
  // A fit on part of the sequence can be checked on the rest with
  // `eval board-poses --camera` (held-out corner RMS).
  AddFrameRangeOptions(cmd, &a->first_frame, &a->num_frames);
  cmd->callback([a]() {
    int cols = 0, rows = 0;
    char tail = 0;
    if (std::sscanf(a->board.c_str(), "%dx%d%c", &cols, &rows, &tail) != 2 ||
        cols < 2 || rows < 2) {
      throw OptionsError("--board: expected COLSxROWS of inner corners, got '" +
                         a->board + "'");
    }
    CheckOutputFile(a->output, {a->dataset});
    a->options.inner_corners_x = cols;
    a->options.inner_corners_y = rows;
    a->options.full_distortion = !a->radial_only;
    DatasetOptions dataset_options;
    dataset_options.load_groundtruth = false;
    dataset_options.first_frame = a->first_frame;
    dataset_options.num_frames = a->num_frames;
    const Dataset dataset = LoadDataset(a->dataset, dataset_options);
    const CalibrationReport report = CalibrateFromCheckerboard(
        [&](int i) { return dataset.LoadImage(static_cast<size_t>(i)); },
        static_cast<int>(dataset.frames.size()), dataset.camera, a->options);
    WriteCameraYaml(a->output, report.camera, "monomap_calibrate");
    const Camera& c = report.camera;
    std::printf(
        "board found in %d of %d frames (corners out to %.0f px from the "
        "centre)\n"
        "corner RMS error: %.3f px with the dataset's calibration, %.3f px "
        "refitted\n"
        "fx %.3f fy %.3f cx %.3f cy %.3f  k1 %.5f k2 %.5f p1 %.5f p2 %.5f "
        "k3 %.5f -> %s\n",
        report.views, report.frames_tried, report.max_corner_radius_px,
        report.initial_rms_px, report.final_rms_px, c.fx, c.fy, c.cx, c.cy,
        c.distortion[0], c.distortion[1], c.distortion[2], c.distortion[3],
        c.distortion[4], a->output.c_str());
  });
}

}  // namespace monomap
