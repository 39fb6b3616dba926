// monomap render MAP_DIR --pose "tx ty tz qx qy qz qw" -o VIEW.png
//                [--depth DEPTH.tiff|.exr] [--size WxH] [--color]
#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <vector>

#include "monomap/exe/cli_parse.h"
#include "monomap/exe/commands.h"
#include "monomap/io/map_format.h"
#include "monomap/io/trajectory_io.h"
#include "monomap/rendering/renderer.h"
#include "monomap/util/error.h"
#include "monomap/util/file.h"

namespace monomap {

namespace {

// Lower-case extension with the dot ("" if none).
std::string Extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return ext;
}

// Checked before rendering, so that a wrong name costs nothing and writes
// nothing. Depth is 32-bit float, which only TIFF and EXR keep (OpenCV
// would silently round it to 8 bits in a PNG).
void CheckOutputNames(const std::string& image, const std::string& depth) {
  if (Extension(image).empty() || !cv::haveImageWriter(image)) {
    throw OptionsError("-o: " + image +
                       ": no image format for this extension (use .png)");
  }
  if (depth.empty()) return;
  const std::string ext = Extension(depth);
  if (ext != ".tiff" && ext != ".tif" && ext != ".exr") {
    throw OptionsError("--depth: " + depth +
                       ": must end in .tiff, .tif or .exr (32-bit float)");
  }
}

std::string EncodeImage(const std::string& path, const cv::Mat& image) {
  std::vector<uchar> bytes;
  bool ok = false;
  try {
    ok = cv::imencode(Extension(path), image, bytes);
  } catch (const cv::Exception& e) {
    throw OutputError(path + ": cannot encode image: " + e.what());
  }
  if (!ok) throw OutputError(path + ": cannot encode image");
  return std::string(bytes.begin(), bytes.end());
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
  cmd->add_option("-o,--output", a->output,
                  "Image to write (PNG; any format OpenCV writes)")
      ->required();
  cmd->add_option("--depth", a->depth,
                  "Also write depth (metres along the optical axis, 0 = "
                  "background) as 32-bit float TIFF or EXR");
  cmd->add_option("--size", a->size,
                  "Image size WxH (default: the map camera's)");
  cmd->add_flag("--color", a->color, "Render in colour");
  cmd->callback([a]() {
    CheckOutputNames(a->output, a->depth);
    CheckOutputFile(a->output, {a->map_dir});
    if (!a->depth.empty()) CheckOutputFile(a->depth, {a->map_dir}, "--depth");
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
    // Both encoded before either is written: no half of the output.
    const std::string image_bytes = EncodeImage(a->output, image);
    const std::string depth_bytes =
        a->depth.empty() ? std::string() : EncodeImage(a->depth, depth);
    WriteFileAtomic(a->output, image_bytes);
    if (!a->depth.empty()) WriteFileAtomic(a->depth, depth_bytes);
  });
}

}  // namespace monomap
