// Anticipatory rendering: what the camera would see of the map's textured
// planes from a given pose. It is the inner loop of particle-filter
// localization, so the renderer precomputes everything it can once (grey
// and optionally colour mip pyramids, premultiplied by alpha, with the
// polygon baked into alpha) and a render is a plain scanline loop: per
// plane a texel_from_pixel homography whose third row is the inverse depth,
// a z-buffer on 1/z, a mip level per short span and a bilinear sample.
#pragma once

#include <memory>
#include <vector>

#include <opencv2/core.hpp>

#include "monomap/camera/camera.h"
#include "monomap/geometry/rigid3.h"
#include "monomap/map/map.h"

namespace monomap {

// Which size of a pixel's texel footprint picks the mip level. Seen
// obliquely, the footprint is a long parallelogram.
enum class MipFootprint {
  // Its area (the geometric mean of its axes): the blur a camera's own box
  // downscaling gives, sharp across the long axis, slightly aliased along
  // it. The default: renders then match area-downscaled live images.
  kArea,
  // Its longest axis (the rule of OpenGL without anisotropic filtering):
  // never aliases, but blurs oblique floors and walls far beyond what a
  // camera sees (floor boards vanish at 160x120).
  kLongestAxis,
};

struct RendererOptions {
  // Filter minified textures with a mip pyramid (2x2 box, premultiplied
  // alpha). Off gives plain bilinear sampling of the full texture (aliases).
  bool use_mipmaps = true;
  // Footprint measure that picks the mip level (see MipFootprint).
  MipFootprint mip_footprint = MipFootprint::kArea;
  // Added to log2(texel footprint) before picking the mip level: > 0 blurs
  // more, < 0 keeps more detail (and aliases more).
  double mip_bias = 0.0;
  // Grey value (and colour, as grey) where no plane is seen.
  int background_grey = 0;
  // A sample counts as seen where its interpolated alpha (0..1) reaches
  // this; 0.5 puts the edge of seen texels / the polygon where it belongs.
  double alpha_threshold = 0.5;
  // Also build BGR pyramids so that RenderColor() works (doubles memory).
  bool enable_color = false;
  // Skip planes seen from behind, i.e. from the side opposite to
  // frame.Normal() = u_axis x v_axis (the side the texture was seen from).
  bool cull_back_faces = true;
  // Surfaces closer than this (m along the optical axis) are not drawn.
  double z_near_m = 0.01;
  // Texels whose centre lies outside TexturedPlane::polygon get alpha 0
  // (a polygon with fewer than 3 vertices means the whole texture).
  bool clip_to_polygon = true;
  // ... to TexturedPlane::landmark_polygon instead, where a plane has one
  // (the part of a grown polygon its landmarks support): localization's
  // choice (LocalizationRendererOptions).
  bool clip_to_landmark_polygon = false;

  // Throws OptionsError naming the field if a value makes no sense.
  void Check() const;
};

// What one render did.
struct RenderStats {
  int planes_in_map = 0;
  // Planes facing the camera that won the z-test on at least one pixel
  // (some may be hidden later by a closer plane).
  int planes_drawn = 0;
  // Pixels showing a plane (the others show background).
  int pixels_foreground = 0;
  int pixels_total = 0;
};

class Renderer {
 public:
  // Precomputes the pyramids of every plane with a texture; planes without
  // texture are ignored. Throws OptionsError on bad options and InputError
  // on a texture that is not 8-bit 1/3/4 channels or a non-positive
  // pixels_per_meter.
  explicit Renderer(const std::vector<TexturedPlane>& planes,
                    const RendererOptions& options = {});
  explicit Renderer(const Map& map, const RendererOptions& options = {});
  ~Renderer();
  Renderer(Renderer&&) noexcept;
  Renderer& operator=(Renderer&&) noexcept;

  // Renders the planes seen by `camera` (used as a pinhole: its distortion
  // is ignored; pass camera.Scaled(w, h) for small renders) at pose
  // world_from_cam. `grey` becomes CV_8UC1 camera.height x camera.width;
  // `depth` (optional) CV_32FC1 with metres along the optical axis, 0 where
  // background. Thread-safe: renders of different poses may run in
  // parallel.
  RenderStats Render(const Camera& camera, const Rigid3d& world_from_cam,
                     cv::Mat* grey, cv::Mat* depth = nullptr) const;
  // The same in colour: `bgr` becomes CV_8UC3. Needs
  // options.enable_color (throws OptionsError otherwise).
  RenderStats RenderColor(const Camera& camera, const Rigid3d& world_from_cam,
                          cv::Mat* bgr, cv::Mat* depth = nullptr) const;

  // Renders every pose (e.g. the particles of a filter) in parallel with
  // oneTBB. greys (and depths if not null) are resized to poses.size();
  // their Mats are reused when they already have the right size.
  std::vector<RenderStats> RenderBatch(const Camera& camera,
                                       const std::vector<Rigid3d>& poses,
                                       std::vector<cv::Mat>* greys,
                                       std::vector<cv::Mat>* depths =
                                           nullptr) const;

  // A renderer of the same planes (the pyramids are shared, not copied)
  // that picks mip levels with another bias.
  Renderer WithMipBias(double mip_bias) const;

  const RendererOptions& options() const { return options_; }
  int num_planes() const;
  // Bytes held by the pyramids (for reports).
  size_t MemoryBytes() const;

 private:
  struct PlaneData;
  struct PlaneView;  // a plane facing the camera, projected into its image
  // Pass 1 of a render: the planes that face the camera and are in view.
  std::vector<PlaneView> ViewPlanes(const Camera& camera,
                                    const Rigid3d& world_from_cam) const;
  template <int C>
  RenderStats RenderImpl(const Camera& camera, const Rigid3d& world_from_cam,
                         cv::Mat* image, cv::Mat* depth) const;

  Renderer() = default;

  RendererOptions options_;
  // Built once, then only read: shared by WithMipBias copies.
  std::vector<std::shared_ptr<const PlaneData>> planes_;
};

}  // namespace monomap
