// monomap render MAP_DIR --pose "tx ty tz qx qy qz qw" -o VIEW.png
//                [--depth DEPTH.tiff|.exr] [--size WxH] [--color]
#include <cstdio>
#include <memory>
#include <opencv2/imgcodecs.hpp>

#include "monomap/exe/cli_parse.h"
#include "monomap/exe/commands.h"
#include "monomap/io/map_format.h"
#include "monomap/io/trajectory_io.h"
#include "monomap/rendering/renderer.h"
#include "monomap/util/error.h"

namespace monomap {

namespace {

void WriteImage(const std::string& path, const cv::Mat& image) {
  bool ok = false;
  try {
    ok = cv::imwrite(path, image);
  } catch (const cv::Exception& e) {
    throw OutputError(path + ": cannot write image: " + e.what());
  }
  if (!ok) throw OutputError(path + ": cannot write image");
}

}  // namespace

void RegisterRenderCommand(CLI::App& app) {
  struct Args {
    std::string map_dir, pose, output, depth, size;
    bool color = false;
  };
  auto a = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "render", "Render the textured planes of a map from a camera pose");
  cmd->add_option("map", a->map_dir, "Map directory")->required();
  cmd->add_option("--pose", a->pose,
                  "Camera pose T_world_cam as \"tx ty tz qx qy qz qw\"")
      ->required();
  cmd->add_option("-o,--output", a->output, "Image to write (PNG)")
      ->required();
  cmd->add_option("--depth", a->depth,
                  "Also write depth (metres along the optical axis, 0 = "
                  "background) as 32-bit float TIFF or EXR");
  cmd->add_option("--size", a->size,
                  "Image size WxH (default: the map camera's)");
  cmd->add_flag("--color", a->color, "Render in colour");
  cmd->callback([a]() {
    const Map map = ReadMap(a->map_dir);
    const Rigid3d world_from_cam = ParsePose(a->pose, "--pose");
    Camera camera = map.camera.Pinhole();
    if (!a->size.empty()) {
      int w = 0, h = 0;
      ParseImageSize(a->size, "--size", &w, &h);
      camera = camera.Scaled(w, h);
    }
    RendererOptions options;
    options.enable_color = a->color;
    const Renderer renderer(map, options);
    cv::Mat image, depth;
    if (a->color) {
      renderer.RenderColor(camera, world_from_cam, &image,
                           a->depth.empty() ? nullptr : &depth);
    } else {
      renderer.Render(camera, world_from_cam, &image,
                      a->depth.empty() ? nullptr : &depth);
    }
    WriteImage(a->output, image);
    if (!a->depth.empty()) WriteImage(a->depth, depth);
  });
}

}  // namespace monomap
