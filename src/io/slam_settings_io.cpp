#include "io/slam_settings_io.hpp"

#include <yaml-cpp/yaml.h>

#include <functional>
#include <map>

#include "common/error.hpp"
#include "io/camera_settings.hpp"
#include "io/yaml_file.hpp"

namespace hiveslam::io {

namespace {

template <typename T>
std::function<void(const YAML::Node&)> set(T& field) {
  return [&field](const YAML::Node& n) { field = n.as<T>(); };
}

using KeyTable = std::map<std::string, std::function<void(const YAML::Node&)>>;

// Sets every key of `section` through `table`; `skip` is a sub-section handled elsewhere.
void apply(const std::filesystem::path& file, const YAML::Node& section, const KeyTable& table,
           const std::string& prefix, const std::string& skip = "") {
  const std::string name = prefix.empty() ? std::string("slam") : prefix.substr(0, prefix.size() - 1);
  if (!section.IsMap()) throw InputError(file.string() + ": '" + name + "' is not a map of settings");
  for (const auto& kv : section) {
    if (!kv.first.IsScalar()) throw InputError(file.string() + ": a key in '" + name + "' is not a name");
    const std::string key = kv.first.Scalar();
    if (key == skip) continue;
    const auto it = table.find(key);
    if (it == table.end()) throw InputError(file.string() + ": unknown setting '" + prefix + key + "'");
    try {
      it->second(kv.second);
    } catch (const YAML::Exception&) {
      throw InputError(file.string() + ": setting '" + prefix + key + "' has the wrong type");
    }
  }
}

KeyTable slamKeys(core::SlamSettings& s) {
  return {
      {"init_min_matches", set(s.init_min_matches)},
      {"init_min_parallax_deg", set(s.init_min_parallax_deg)},
      {"init_min_points", set(s.init_min_points)},
      {"search_radius_last_frame", set(s.search_radius_last_frame)},
      {"min_matches_last_frame", set(s.min_matches_last_frame)},
      {"min_inliers_tracking", set(s.min_inliers_tracking)},
      {"min_inliers_after_relocalization", set(s.min_inliers_after_relocalization)},
      {"local_keyframes", set(s.local_keyframes)},
      {"keyframe_min_frames", set(s.keyframe_min_frames)},
      {"keyframe_max_frames", set(s.keyframe_max_frames)},
      {"keyframe_ratio", set(s.keyframe_ratio)},
      {"keyframe_weak_ratio", set(s.keyframe_weak_ratio)},
      {"keyframe_turn_deg", set(s.keyframe_turn_deg)},
      {"keyframe_min_inliers", set(s.keyframe_min_inliers)},
      {"lost_frames_before_new_map", set(s.lost_frames_before_new_map)},
      {"relocalize_in_every_map", set(s.relocalize_in_every_map)},
      {"triangulation_neighbours", set(s.triangulation_neighbours)},
      {"triangulation_max_cos_parallax", set(s.triangulation_max_cos_parallax)},
      {"triangulation_by_vocabulary", set(s.triangulation_by_vocabulary)},
      {"triangulation_look_alike_ratio", set(s.triangulation_look_alike_ratio)},
      {"fusion_neighbours", set(s.fusion_neighbours)},
      {"local_ba_iterations", set(s.local_ba_iterations)},
      {"keyframe_queue", set(s.keyframe_queue)},
      {"redundant_keyframe_ratio", set(s.redundant_keyframe_ratio)},
      {"keyframe_culling_max_angle_deg", set(s.keyframe_culling_max_angle_deg)},
      {"loop_closing", set(s.loop_closing)},
      {"loop_min_keyframes", set(s.loop_min_keyframes)},
      {"loop_consistency", set(s.loop_consistency)},
      {"loop_min_bow_matches", set(s.loop_min_bow_matches)},
      {"loop_min_sim3_inliers", set(s.loop_min_sim3_inliers)},
      {"loop_min_total_matches", set(s.loop_min_total_matches)},
      {"loop_min_inlier_ratio", set(s.loop_min_inlier_ratio)},
      {"loop_max_scale_change", set(s.loop_max_scale_change)},
      {"essential_graph_min_weight", set(s.essential_graph_min_weight)},
      {"essential_graph_iterations", set(s.essential_graph_iterations)},
      {"global_ba_iterations", set(s.global_ba_iterations)},
      {"global_ba_noise_factor", set(s.global_ba_noise_factor)},
      {"global_ba_outliers_from_start", set(s.global_ba_outliers_from_start)},
      {"global_ba_every_keyframes", set(s.global_ba_every_keyframes)},
      {"final_global_ba_iterations", set(s.final_global_ba_iterations)},
      {"remeasure", set(s.remeasure)},
      {"remeasure_image_budget_mb", set(s.remeasure_image_budget_mb)},
      {"refine_frames", set(s.refine_frames)},
      {"refine_frames_window", set(s.refine_frames_window)},
      {"vocabulary", set(s.vocabulary)},
      {"seed", set(s.seed)},
  };
}

KeyTable orbKeys(features::OrbOptions& o) {
  return {
      {"features", set(o.features)},
      {"scale_factor", set(o.scale_factor)},
      {"levels", set(o.levels)},
      {"fast_threshold", set(o.fast_threshold)},
      {"min_fast_threshold", set(o.min_fast_threshold)},
      {"cell_size", set(o.cell_size)},
      {"subpixel", set(o.subpixel)},
  };
}

KeyTable distributionKeys(distribution::DistributionSettings& s) {
  return {
      {"local_first_batch", set(s.local_first_batch)},
      {"local_max_batch", set(s.local_max_batch)},
      {"local_batch_gap_ms", set(s.local_batch_gap_ms)},
      {"local_window", set(s.local_window)},
      {"min_point_move", set(s.min_point_move)},
      {"point_descriptor_bits", set(s.point_descriptor_bits)},
      {"point_normal_deg", set(s.point_normal_deg)},
      {"point_range_ratio", set(s.point_range_ratio)},
      {"global_batch", set(s.global_batch)},
      {"global_batch_gap_ms", set(s.global_batch_gap_ms)},
      {"lc_global_batch_gap_ms", set(s.lc_global_batch_gap_ms)},
      {"remote_mapping_wait_ms", set(s.remote_mapping_wait_ms)},
      {"handover_wait_ms", set(s.handover_wait_ms)},
      {"release_slow_gateway_ms", set(s.release_slow_gateway_ms)},
      {"release_slow_acks", set(s.release_slow_acks)},
      {"dead_peer_ms", set(s.dead_peer_ms)},
  };
}

KeyTable ddsKeys(communication::DdsOptions& o) {
  return {
      {"max_datagram_bytes", set(o.max_datagram_bytes)},
      {"heartbeat_ms", set(o.heartbeat_ms)},
      {"history_depth", set(o.history_depth)},
      {"leave_flush_ms", set(o.leave_flush_ms)},
  };
}

KeyTable viewKeys(viz::ViewSettings& v) {
  return {
      {"pose_hz", set(v.pose_hz)},     {"path_hz", set(v.path_hz)},   {"cloud_hz", set(v.cloud_hz)},
      {"status_hz", set(v.status_hz)}, {"image_hz", set(v.image_hz)}, {"web_kbytes_per_s", set(v.web_kbytes_per_s)},
  };
}

}  // namespace

std::vector<std::string> settingKeys() {
  core::SlamSettings slam;
  distribution::DistributionSettings distribution;
  communication::DdsOptions dds;
  std::vector<std::string> keys;
  for (const auto& key : cameraSettingKeys()) keys.push_back("camera." + key);
  for (const auto& [key, set] : slamKeys(slam)) keys.push_back("slam." + key);
  for (const auto& [key, set] : orbKeys(slam.orb)) keys.push_back("slam.orb." + key);
  for (const auto& [key, set] : distributionKeys(distribution)) keys.push_back("distribution." + key);
  for (const auto& [key, set] : ddsKeys(dds)) keys.push_back("dds." + key);
  viz::ViewSettings view;
  for (const auto& [key, set] : viewKeys(view)) keys.push_back("view." + key);
  return keys;
}

void applySlamSettings(const std::filesystem::path& file, core::SlamSettings& s) {
  const YAML::Node root = loadYamlMap(file);
  const YAML::Node slam = root["slam"];
  if (!slam) return;
  apply(file, slam, slamKeys(s), "", "orb");
  if (slam["orb"]) apply(file, slam["orb"], orbKeys(s.orb), "orb.");
  // The extractor divides by the cell size and indexes its pyramid by level: out of these
  // ranges it reads outside its buffers (fuzzer findings: levels 0, cell_size 0 and -7).
  const auto& o = s.orb;
  if (o.features < 1 || o.levels < 1 || o.levels > 32 || !(o.scale_factor >= 1.0 && o.scale_factor <= 4.0) ||
      o.fast_threshold < 1 || o.fast_threshold > 255 || o.min_fast_threshold < 1 || o.min_fast_threshold > 255 ||
      o.cell_size < 8 || o.cell_size > 1024)
    throw InputError(file.string() + ": slam.orb settings out of range (features >= 1, levels 1-32, scale_factor 1-4, "
                     "FAST thresholds 1-255, cell_size 8-1024)");
  if (!(s.loop_max_scale_change >= 1.0))
    throw InputError(file.string() + ": slam.loop_max_scale_change must be at least 1 (a ratio either way)");
}

void applyDistributionSettings(const std::filesystem::path& file, distribution::DistributionSettings& s) {
  const YAML::Node section = loadYamlMap(file)["distribution"];
  if (!section) return;
  apply(file, section, distributionKeys(s), "distribution.");
  if (s.local_first_batch < 1 || s.local_max_batch < s.local_first_batch || s.global_batch < 1 ||
      s.local_batch_gap_ms < 0 || s.global_batch_gap_ms < 0 || s.lc_global_batch_gap_ms < 0 || s.local_window < 1 ||
      s.min_point_move < 0 || s.point_descriptor_bits < 0 || s.point_normal_deg < 0 || s.point_range_ratio < 0 ||
      s.remote_mapping_wait_ms < 0 || s.handover_wait_ms < 0 || s.release_slow_gateway_ms < 0 ||
      s.release_slow_acks < 0 || s.dead_peer_ms < 0)
    throw InputError(file.string() + ": distribution settings out of range (batches and local_window >= 1, first <= max, times, "
                     "min_point_move and point tolerances >= 0)");
}

void applyDdsSettings(const std::filesystem::path& file, communication::DdsOptions& o) {
  const YAML::Node section = loadYamlMap(file)["dds"];
  if (!section) return;
  apply(file, section, ddsKeys(o), "dds.");
  // 576 bytes: the datagram every IPv4 host must take whole; 65500: UDP's limit.
  if (o.max_datagram_bytes < 576 || o.max_datagram_bytes > 65500 || o.heartbeat_ms < 1 || o.heartbeat_ms > 60000 ||
      o.history_depth < 1 || o.leave_flush_ms < 0)
    throw InputError(file.string() + ": dds settings out of range (max_datagram_bytes 576-65500, heartbeat_ms 1-60000, "
                     "history_depth >= 1, leave_flush_ms >= 0)");
}

void applyViewSettings(const std::filesystem::path& file, viz::ViewSettings& v) {
  const YAML::Node section = loadYamlMap(file)["view"];
  if (!section) return;
  apply(file, section, viewKeys(v), "view.");
  // Rates above 100 Hz would only cost CPU: no display or ROS tool draws faster.
  const auto rate_ok = [](double hz) { return hz > 0 && hz <= 100; };
  if (!rate_ok(v.pose_hz) || !rate_ok(v.path_hz) || !rate_ok(v.cloud_hz) || !rate_ok(v.status_hz) || !rate_ok(v.image_hz) ||
      v.web_kbytes_per_s < 1)
    throw InputError(file.string() + ": view settings out of range (rates above 0 and at most 100 Hz, web_kbytes_per_s >= 1)");
}

}  // namespace hiveslam::io
