#include "ros/node_options.h"

#include <algorithm>
#include <vector>

#include "monomap/util/error.h"

namespace monomap::ros_adapter {
namespace {

// A pose parameter: [tx, ty, tz, qx, qy, qz, qw] (the CLI's --init-pose).
std::optional<Rigid3d> ReadPose(const ros::NodeHandle& pnh,
                                const std::string& name) {
  std::vector<double> v;
  if (!pnh.getParam(name, v)) {
    if (pnh.hasParam(name)) {
      throw OptionsError("~" + name + ": must be a list of 7 numbers");
    }
    return std::nullopt;
  }
  if (v.size() != 7) {
    throw OptionsError("~" + name + ": must be [tx, ty, tz, qx, qy, qz, qw]");
  }
  const Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);
  if (q.norm() < 1e-9) throw OptionsError("~" + name + ": zero quaternion");
  return Rigid3d(q.normalized(), Eigen::Vector3d(v[0], v[1], v[2]));
}

// "WxH" into width and height (the CLI's --mcc-size, --measure-size).
void ReadSize(const ros::NodeHandle& pnh, const std::string& name, int* width,
              int* height) {
  std::string s;
  if (!pnh.getParam(name, s)) return;
  int w = 0, h = 0;
  char x = 0, extra = 0;
  if (std::sscanf(s.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 ||
      x != 'x' || w < 8 || h < 8) {
    throw OptionsError("~" + name + ": '" + s + "' is not WxH (e.g. 160x120)");
  }
  *width = w;
  *height = h;
}

template <typename T>
T Parse(const std::string& name, const std::string& value,
        T (*parse)(const std::string&)) {
  try {
    return parse(value);
  } catch (const Error& e) {
    throw OptionsError("~" + name + ": " + e.what());
  }
}

// The filter's options, as `monomap localize` resolves its flags.
void ReadLocalizerOptions(const ros::NodeHandle& pnh, LocalizerOptions* o) {
  std::string method = "mcl", state = "planar", init = "pose";
  pnh.param<std::string>("method", method, method);
  pnh.param<std::string>("state", state, state);
  pnh.param<std::string>("init", init, init);
  o->method = Parse("method", method, ParseLocalizationMethod);
  o->state = Parse("state", state, ParseLocalizationState);
  o->init.kind = Parse("init", init, ParseLocalizationInit);
  o->init.pose = ReadPose(pnh, "init_pose");
  if (o->init.pose && o->init.kind != LocalizationInit::kPose) {
    throw OptionsError("~init_pose needs ~init pose");
  }
  pnh.param("init_spread_m", o->init.spread_m, o->init.spread_m);
  pnh.param("init_spread_deg", o->init.spread_deg, o->init.spread_deg);
  pnh.param("particles", o->mcl.num_particles, o->mcl.num_particles);
  o->mcl.SetParticleBudget(o->mcl.num_particles);
  pnh.param("mcc_top_k", o->mcc.top_k, o->mcc.top_k);
  pnh.param("relocalize_ncc_drop", o->recovery.relocalize_ncc_drop,
            o->recovery.relocalize_ncc_drop);
  ReadSize(pnh, "mcc_size", &o->mcc.corrector.width, &o->mcc.corrector.height);
  ReadSize(pnh, "measure_size", &o->mcl.measurement.width,
           &o->mcl.measurement.height);
  int refine_width = EstimateRefinementWidth(o->mcc);
  pnh.param("refine_width", refine_width, refine_width);
  SetEstimateRefinementWidth(refine_width, "~refine_width", &o->mcc);
  pnh.param("refine_converged_px", o->mcc.refinement.converged_px,
            o->mcc.refinement.converged_px);
  int seed = int(o->seed);
  pnh.param("seed", seed, seed);
  o->seed = uint64_t(seed);
}

void ReadSessionOptions(const ros::NodeHandle& pnh, SessionOptions* s) {
  pnh.param("drop_when_busy", s->drop_when_busy, s->drop_when_busy);
  pnh.param("max_pending_frames", s->max_pending_frames,
            s->max_pending_frames);
  pnh.param("lost_after_updates", s->lost_after_updates,
            s->lost_after_updates);
  pnh.param("min_stamp_step", s->min_stamp_step_s, s->min_stamp_step_s);
  pnh.param("publish_particles", s->output_particles, s->output_particles);
}

}  // namespace

NodeOptions ReadNodeOptions(const ros::NodeHandle& pnh) {
  NodeOptions n;
  if (!pnh.getParam("map_dir", n.map_dir) || n.map_dir.empty()) {
    throw OptionsError("~map_dir: required (the map directory)");
  }
  ReadLocalizerOptions(pnh, &n.session.localizer);
  ReadSessionOptions(pnh, &n.session);
  pnh.param("odom_source", n.odom_source, n.odom_source);
  if (n.odom_source != "odom" && n.odom_source != "tf") {
    throw OptionsError("~odom_source: '" + n.odom_source +
                       "' is not odom or tf");
  }
  pnh.param("compressed", n.compressed, n.compressed);
  pnh.param("global_frame_id", n.global_frame, n.global_frame);
  pnh.param("odom_frame_id", n.odom_frame, n.odom_frame);
  pnh.param("base_frame_id", n.base_frame, n.base_frame);
  n.base_from_cam = ReadPose(pnh, "base_from_camera");
  pnh.param("camera_frame_id", n.camera_frame, n.camera_frame);
  pnh.param("transform_tolerance", n.transform_tolerance,
            n.transform_tolerance);
  pnh.param("camera_info_tolerance_px", n.camera_info_tolerance_px,
            n.camera_info_tolerance_px);
  pnh.param("odom_buffer", n.odom_buffer_s, n.odom_buffer_s);
  pnh.param("odom_max_gap", n.odom_max_gap_s, n.odom_max_gap_s);
  pnh.param("odom_wait", n.odom_wait_s, n.odom_wait_s);
  n.session.Check();
  return n;
}

}  // namespace monomap::ros_adapter
