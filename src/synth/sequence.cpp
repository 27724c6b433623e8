#include "synth/sequence.hpp"

#include <fmt/format.h>
#include <fmt/os.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <fstream>
#include <mutex>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <thread>

#include "common/error.hpp"
#include "synth/renderer.hpp"

namespace hiveslam::synth {

namespace fs = std::filesystem;

namespace {

constexpr int64_t kStartNs = 1'000'000'000'000;  // 1000 s: EuRoC-like stamps, exact in ns

Eigen::Vector3d roomSize(std::mt19937_64& rng) {
  auto uni = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
  return {uni(8.5, 11.5), uni(6.5, 8.5), uni(2.8, 3.4)};
}

}  // namespace

SequenceModel buildSequence(const SequenceOptions& o) {
  if (o.frames < 2) throw InputError("a sequence needs at least 2 frames");
  if (o.width < 32 || o.height < 32) throw InputError("image size must be at least 32x32");
  if (o.fps <= 0) throw InputError("fps must be positive");
  // Separate streams for layout, path and textures keep one from shifting the others.
  std::mt19937_64 layout_rng(o.seed * 7919 + 1), path_rng(o.seed * 7919 + 2), scene_rng(o.seed * 7919 + 3);
  SceneOptions scene_options;
  scene_options.room_size = roomSize(layout_rng);
  if (!o.textures.empty()) scene_options.photos = loadPhotos(o.textures);
  TrajectoryPlan plan = planTrajectory(o.trajectory, scene_options.room_size, path_rng);
  const double duration = (o.frames - 1) / o.fps;
  CameraPath path(plan.waypoints, duration, 0.03, static_cast<unsigned>(o.seed));
  Scene scene = makeScene(scene_options, path.samples(0.1), scene_rng);
  return SequenceModel{o, Lens::standard(o.width, o.height, o.distortion), std::move(scene),
                       std::move(path), std::move(plan)};
}

double SequenceModel::stamp(int frame) const { return static_cast<double>(stampNs(frame)) / 1e9; }

int64_t SequenceModel::stampNs(int frame) const {
  return kStartNs + static_cast<int64_t>(std::llround(frame * 1e9 / options.fps));
}

Eigen::Isometry3d SequenceModel::pose(int frame) const { return path.pose(frame / options.fps); }

bool SequenceModel::blank(int frame) const {
  const double u = path.paramAt(frame / options.fps);
  for (auto [from, to] : plan.blank)
    if (u >= from && u < to) return true;
  return false;
}

cv::Mat SequenceModel::renderImage(int frame, const RayTable& rays) const {
  cv::Mat radiance(rays.height, rays.width, CV_32F, cv::Scalar(0));
  const double t = frame / options.fps;
  if (!blank(frame)) {
    if (options.motion_blur) {
      // A 10 ms exposure centred on the stamp, 5 sub-frames.
      constexpr int kSub = 5;
      cv::Mat sub;
      for (int k = 0; k < kSub; ++k) {
        renderRadiance(scene, rays, path.pose(t + 0.010 * ((k + 0.5) / kSub - 0.5)), sub);
        radiance += sub / kSub;
      }
    } else {
      renderRadiance(scene, rays, path.pose(t), radiance);
    }
    if (options.exposure_changes)
      radiance *= 1.0 + 0.25 * std::sin(2 * M_PI * t / 17.0) * std::sin(2 * M_PI * t / 5.3 + 1.0);
  }
  if (options.noise > 0) {
    cv::Mat noise(radiance.size(), CV_32F);
    cv::RNG rng(options.seed * 1000003ULL + static_cast<uint64_t>(frame));
    rng.fill(noise, cv::RNG::NORMAL, 0.0, options.noise);
    radiance += noise;
  }
  cv::Mat image;
  radiance.convertTo(image, CV_8U);  // rounds and saturates
  return image;
}

SequenceSummary writeSequence(const SequenceOptions& o, const fs::path& out,
                              const std::function<void(int, int)>& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  const SequenceModel model = buildSequence(o);
  const RayTable rays(model.lens);
  const fs::path cam0 = out / "mav0" / "cam0";
  const fs::path gt_dir = out / "mav0" / "state_groundtruth_estimate0";
  std::error_code ec;
  fs::create_directories(cam0 / "data", ec);
  fs::create_directories(gt_dir, ec);
  if (ec || !fs::is_directory(cam0 / "data"))
    throw InputError("cannot create output folder " + (cam0 / "data").string());

  // Frames in parallel; each worker renders and encodes whole frames.
  const int threads = o.threads > 0 ? o.threads : std::max(1u, std::thread::hardware_concurrency());
  std::atomic<int> next{0}, done{0};
  // One encoder at a time: TSan reports a race inside OpenCV's image codecs when two threads
  // call imwrite together. Encoding is ~15% of a frame's time, so rendering stays parallel.
  std::mutex error_mutex, progress_mutex, encode_mutex;
  std::string error;
  auto work = [&]() {
    for (int f = next++; f < o.frames; f = next++) {
      const cv::Mat image = model.renderImage(f, rays);
      const fs::path file = cam0 / "data" / fmt::format("{}.png", model.stampNs(f));
      bool written = false;
      {
        std::lock_guard lock(encode_mutex);
        written = cv::imwrite(file.string(), image);
      }
      if (!written) {
        std::lock_guard lock(error_mutex);
        error = "cannot write " + file.string();
      }
      const int d = ++done;
      if (progress) {
        std::lock_guard lock(progress_mutex);
        progress(d, o.frames);
      }
    }
  };
  std::vector<std::thread> pool;
  for (int i = 0; i < threads; ++i) pool.emplace_back(work);
  for (auto& t : pool) t.join();
  if (!error.empty()) throw InputError(error);

  SequenceSummary summary;
  summary.frames = o.frames;
  {
    auto csv = fmt::output_file((cam0 / "data.csv").string());
    csv.print("#timestamp [ns],filename\n");
    auto gt = fmt::output_file((gt_dir / "data.csv").string());
    gt.print("#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], "
             "q_RS_y [], q_RS_z []\n");
    for (int f = 0; f < o.frames; ++f) {
      csv.print("{},{}.png\n", model.stampNs(f), model.stampNs(f));
      const Eigen::Isometry3d T = model.pose(f);
      const Eigen::Quaterniond q(T.linear());
      const Eigen::Vector3d p = T.translation();
      gt.print("{},{:.9f},{:.9f},{:.9f},{:.12f},{:.12f},{:.12f},{:.12f}\n", model.stampNs(f), p.x(),
               p.y(), p.z(), q.w(), q.x(), q.y(), q.z());
      if (model.blank(f)) ++summary.blank_frames;
    }
  }
  const Lens& l = model.lens;
  {
    std::ofstream yaml(cam0 / "sensor.yaml");
    yaml << "# hiveslam synthetic camera (camera = body, so ground truth is the camera pose)\n"
         << "sensor_type: camera\ncomment: hiveslam synth " << o.trajectory << " seed " << o.seed << "\n"
         << "T_BS:\n  cols: 4\n  rows: 4\n  data: [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0]\n"
         << "rate_hz: " << o.fps << "\n"
         << "resolution: [" << l.width << ", " << l.height << "]\n"
         << "camera_model: pinhole\n"
         << fmt::format("intrinsics: [{:.9g}, {:.9g}, {:.9g}, {:.9g}] #fu, fv, cu, cv\n", l.fx, l.fy, l.cx, l.cy)
         << "distortion_model: radial-tangential\n"
         << fmt::format("distortion_coefficients: [{:.9g}, {:.9g}, {:.9g}, {:.9g}]\n", l.k[0], l.k[1], l.k[2], l.k[3]);
  }
  summary.path_length = model.path.length();
  summary.duration = (o.frames - 1) / o.fps;
  summary.render_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  nlohmann::json info = {{"generator", "hiveslam synth"},
                         {"trajectory", o.trajectory},
                         {"description", model.plan.description},
                         {"seed", o.seed},
                         {"frames", o.frames},
                         {"blank_frames", summary.blank_frames},
                         {"fps", o.fps},
                         {"size", {l.width, l.height}},
                         {"distortion", o.distortion},
                         {"noise", o.noise},
                         {"motion_blur", o.motion_blur},
                         {"exposure_changes", o.exposure_changes},
                         {"textures", o.textures.empty() ? "procedural" : o.textures},
                         {"room_size", {model.scene.room_max.x() * 2, model.scene.room_max.y() * 2, model.scene.room_max.z()}},
                         {"boxes", model.scene.boxes.size()},
                         {"pillars", model.scene.pillars.size()},
                         {"path_length_m", summary.path_length},
                         {"duration_s", summary.duration}};
  std::ofstream(out / "sequence.json") << info.dump(2) << "\n";
  return summary;
}

SequenceOptions readSequenceOptions(const fs::path& dataset) {
  const fs::path file = dataset / "sequence.json";
  std::ifstream in(file);
  if (!in) throw InputError("not a synthetic sequence (no " + file.string() + ")");
  const auto info = nlohmann::json::parse(in, nullptr, false);
  if (info.is_discarded() || !info.is_object()) throw InputError(file.string() + " is not JSON");
  try {
    SequenceOptions o;
    o.trajectory = info.at("trajectory").get<std::string>();
    o.seed = info.at("seed").get<uint64_t>();
    o.frames = info.at("frames").get<int>();
    o.fps = info.at("fps").get<double>();
    o.width = info.at("size").at(0).get<int>();
    o.height = info.at("size").at(1).get<int>();
    o.distortion = info.at("distortion").get<bool>();
    o.noise = info.at("noise").get<double>();
    o.motion_blur = info.at("motion_blur").get<bool>();
    o.exposure_changes = info.at("exposure_changes").get<bool>();
    const auto textures = info.at("textures").get<std::string>();
    if (textures != "procedural") o.textures = textures;
    return o;
  } catch (const nlohmann::json::exception& e) {
    throw InputError(file.string() + ": not what hiveslam synth writes (" + e.what() + ")");
  }
}

}  // namespace hiveslam::synth
