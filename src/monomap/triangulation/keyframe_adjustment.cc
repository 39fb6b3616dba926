#include "monomap/triangulation/keyframe_adjustment.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>
#include <utility>

#include "monomap/util/angles.h"
#include "monomap/util/error.h"

namespace monomap {

void KeyframeOptions::Check() const {
  CheckOption(interval >= 1, "mapping.keyframe_interval", "must be >= 1");
  CheckOption(long_sequence_min_keyframes >= 0,
              "mapping.long_sequence_min_keyframes", "must be >= 0 (0: never)");
  CheckOption(long_min_distance_m >= 0.0,
              "mapping.long_min_keyframe_distance_m", "must be >= 0");
  CheckOption(long_min_angle_deg >= 0.0, "mapping.long_min_keyframe_angle_deg",
              "must be >= 0");
  CheckOption(max_covisibility == 0.0 || max_covisibility >= 3.0,
              "mapping.max_keyframe_covisibility",
              "must be >= 3 (a point counts once seen by 3 keyframes) or 0");
}

std::vector<int> SelectKeyframes(const std::vector<Rigid3d>& world_from_cam,
                                 const KeyframeOptions& options) {
  options.Check();
  const int num_frames = static_cast<int>(world_from_cam.size());
  std::vector<int> keyframes;
  for (int i = 0; i < num_frames; i += options.interval) keyframes.push_back(i);
  const bool long_sequence =
      options.long_sequence_min_keyframes > 0 &&
      static_cast<int>(keyframes.size()) > options.long_sequence_min_keyframes;
  if (long_sequence) {
    keyframes = {0};
    for (int i = options.interval; i < num_frames; ++i) {
      const int last = keyframes.back();
      if (i - last < options.interval) continue;
      const Rigid3d motion = world_from_cam[last].Inverse() * world_from_cam[i];
      if (motion.translation.norm() >= options.long_min_distance_m ||
          RadToDeg(AngleBetween(world_from_cam[last].rotation,
                                world_from_cam[i].rotation)) >=
              options.long_min_angle_deg) {
        keyframes.push_back(i);
      }
    }
  }
  if (num_frames > 0 && keyframes.back() != num_frames - 1) {
    keyframes.push_back(num_frames - 1);
  }
  return keyframes;
}

double KeyframeCovisibility(const std::vector<Track>& tracks,
                            const std::vector<int>& keyframes, int num_frames) {
  std::vector<bool> is_key(num_frames, false);
  for (int f : keyframes) is_key[f] = true;
  double sum_k = 0.0, sum_k2 = 0.0;
  for (const Track& t : tracks) {
    int k = 0;
    for (const Observation& o : t.observations) {
      if (o.frame >= 0 && o.frame < num_frames && is_key[o.frame]) ++k;
    }
    if (k < 3) continue;
    sum_k += k;
    sum_k2 += static_cast<double>(k) * k;
  }
  return sum_k > 0.0 ? sum_k2 / sum_k : 0.0;
}

std::vector<int> ThinKeyframes(const std::vector<Track>& tracks,
                               const std::vector<int>& keyframes,
                               int num_frames, const KeyframeOptions& options,
                               int* thinning) {
  options.Check();
  *thinning = 1;
  if (options.max_covisibility <= 0.0 || keyframes.size() < 3) return keyframes;
  std::vector<int> kept = keyframes;
  // Keeping every m-th keyframe divides each track's count by about m; the
  // loop takes the next m if rounding left it above the bound.
  double covisibility = KeyframeCovisibility(tracks, kept, num_frames);
  while (covisibility > options.max_covisibility && kept.size() > 3) {
    *thinning = std::max(
        *thinning + 1,
        static_cast<int>(std::ceil(*thinning * covisibility /
                                   options.max_covisibility)));
    kept.clear();
    for (size_t k = 0; k < keyframes.size(); k += *thinning) {
      kept.push_back(keyframes[k]);
    }
    if (kept.back() != keyframes.back()) kept.push_back(keyframes.back());
    covisibility = KeyframeCovisibility(tracks, kept, num_frames);
  }
  return kept;
}

namespace {

// The tracks' observations in keyframes, renumbered to keyframe indices;
// tracks seen by fewer than 3 keyframes are left out.
std::vector<Track> KeyframeTracks(const std::vector<Track>& tracks,
                                  const std::vector<int>& key_index) {
  std::vector<Track> key_tracks;
  for (const Track& t : tracks) {
    Track kt;
    kt.id = t.id;
    for (const Observation& o : t.observations) {
      if (key_index[o.frame] >= 0)
        kt.observations.push_back({key_index[o.frame], o.px});
    }
    if (kt.observations.size() >= 3) key_tracks.push_back(std::move(kt));
  }
  return key_tracks;
}

// Applies the keyframes' world-side corrections (adjusted * odometry^-1)
// to every frame, interpolated between keyframes.
void InterpolateCorrections(const std::vector<int>& keyframes,
                            const std::vector<Rigid3d>& key_poses,
                            std::vector<Rigid3d>* world_from_cam) {
  std::vector<Rigid3d> corrections;
  for (size_t k = 0; k < keyframes.size(); ++k) {
    corrections.push_back(key_poses[k] *
                          (*world_from_cam)[keyframes[k]].Inverse());
  }
  for (size_t k = 0; k + 1 < keyframes.size(); ++k) {
    const int a = keyframes[k], b = keyframes[k + 1];
    for (int i = a; i < b; ++i) {
      const double t = static_cast<double>(i - a) / (b - a);
      (*world_from_cam)[i] =
          Interpolate(corrections[k], corrections[k + 1], t) *
          (*world_from_cam)[i];
    }
  }
  world_from_cam->back() = key_poses.back();
}

}  // namespace

BundleAdjustmentReport BundleAdjustKeyframes(
    const Camera& camera, const std::vector<Track>& tracks,
    const BundleAdjustmentOptions& options,
    const KeyframeOptions& keyframe_options,
    std::vector<Rigid3d>* world_from_cam, std::vector<Landmark>* landmarks) {
  const int num_frames = static_cast<int>(world_from_cam->size());
  for (const Track& t : tracks) {
    for (const Observation& o : t.observations) {
      if (o.frame < 0 || o.frame >= num_frames) {
        throw InputError("bundle adjustment: track " + std::to_string(t.id) +
                         " observed in frame " + std::to_string(o.frame) +
                         " which has no pose");
      }
    }
  }
  int thinning = 1;
  const std::vector<int> keyframes =
      ThinKeyframes(tracks, SelectKeyframes(*world_from_cam, keyframe_options),
                    num_frames, keyframe_options, &thinning);
  if (static_cast<int>(keyframes.size()) == num_frames) {
    return BundleAdjust(camera, tracks, options, world_from_cam, landmarks);
  }
  std::vector<int> key_index(num_frames, -1);
  for (size_t k = 0; k < keyframes.size(); ++k) {
    key_index[keyframes[k]] = static_cast<int>(k);
  }
  const std::vector<Track> key_tracks = KeyframeTracks(tracks, key_index);
  std::unordered_map<FeatureId, bool> usable;
  for (const Track& t : key_tracks) usable[t.id] = true;
  std::vector<Landmark> key_landmarks;
  for (const Landmark& l : *landmarks) {
    if (usable.count(l.id)) key_landmarks.push_back(l);
  }
  std::vector<Rigid3d> key_poses;
  for (int f : keyframes) key_poses.push_back((*world_from_cam)[f]);
  BundleAdjustmentReport report =
      BundleAdjust(camera, key_tracks, options, &key_poses, &key_landmarks);
  report.keyframe_thinning = thinning;
  InterpolateCorrections(keyframes, key_poses, world_from_cam);
  *landmarks = std::move(key_landmarks);
  return report;
}

}  // namespace monomap
