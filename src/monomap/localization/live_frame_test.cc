#include "monomap/localization/live_frame.h"

#include <gtest/gtest.h>

#include "monomap/sim/test_scene.h"
#include "monomap/util/error.h"

namespace monomap {
namespace {

TEST(LiveFrame, PreparesEachAskedSizeOnce) {
  const Map map = testing::RoomMap();
  const Renderer renderer(map);
  const Camera camera = testing::LiveCamera();
  const MeasurementModel model(&renderer, camera);
  const cv::Mat raw = testing::LiveImage(
      renderer, camera,
      WorldFromCamOfBase({0.5, 0.2, 0.4}, testing::BaseFromCam()), 0.9, 5,
      2.0, 1);
  LiveFrameSizes sizes;
  sizes.measurement = {80, 60};
  sizes.correction = ImageSize{160, 120};
  const LiveFrame live(raw, model.preparer(), sizes);
  EXPECT_EQ(live.measurement().size(), cv::Size(80, 60));
  EXPECT_EQ(live.correction().size(), cv::Size(160, 120));
  EXPECT_TRUE(live.refinement().empty());
  // The measurement image is the model's own preparation, pixel for pixel.
  EXPECT_EQ(cv::norm(live.measurement(), model.PrepareLive(raw), cv::NORM_INF),
            0.0);
  // A raw image of another size is refused.
  EXPECT_THROW(LiveFrame(cv::Mat(10, 10, CV_8UC1, cv::Scalar(0)),
                         model.preparer(), sizes),
               InputError);
}

}  // namespace
}  // namespace monomap
