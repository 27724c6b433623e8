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

double photoMaxLookAlikes(const SequenceOptions& o) {
  if (o.photo_max_look_alikes >= 0) return o.photo_max_look_alikes;
  return o.realistic ? 0.35 : 1.0;
}

Eigen::Vector3d roomSize(std::mt19937_64& rng, bool furnished) {
  auto uni = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
  // A furnished room is an office or a living room; the textured box room is a hall.
  if (furnished) return {uni(5.0, 6.5), uni(4.0, 5.2), uni(2.5, 2.8)};
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
  scene_options.room_size = roomSize(layout_rng, o.realistic);
  scene_options.furnished = o.realistic;
  if (!o.textures.empty()) scene_options.photos = loadPhotos(o.textures, photoMaxLookAlikes(o));
  TrajectoryPlan plan = planTrajectory(o.trajectory, scene_options.room_size, path_rng);
  const double duration = (o.frames - 1) / o.fps;
  CameraPath path(plan.waypoints, duration, 0.03, static_cast<unsigned>(o.seed));
  if (o.realistic) path.setTremor(o.tremor_deg >= 0 ? o.tremor_deg : 0.3, o.tremor_deg == 0 ? 0.0 : 0.002);
  Scene scene = makeScene(scene_options, path.samples(0.1), scene_rng);
  Lens lens = Lens::standard(o.width, o.height, o.distortion);
  Imaging imaging;
  if (o.realistic) {
    // A Kinect-like 62 x 48 degree field of view: fx 525 at 640 pixels.
    lens.fx = lens.fy = 525.0 * o.width / 640.0;
    imaging = Imaging::realistic();
    if (o.exposure_ms >= 0) imaging.exposure_s = o.exposure_ms / 1000.0;
    if (o.readout_ms >= 0) imaging.readout_s = o.readout_ms / 1000.0;
    if (o.denoise >= 0) imaging.denoise_sigma = o.denoise;
    if (!o.lens_error) {
      imaging.focal_error = imaging.hidden_k1 = 0;
      imaging.principal_error_px[0] = imaging.principal_error_px[1] = 0;
    }
  } else if (o.motion_blur) {
    imaging.exposure_s = 0.010;
    imaging.max_sub_frames = 5;
  }
  SequenceModel model{o, lens, imaging.trueLens(lens), std::move(scene), std::move(path), std::move(plan), imaging,
                      {}, imaging.vignette(o.width, o.height)};
  if (imaging.auto_exposure) {
    // What the camera's metering sees: each frame at an eighth of the resolution, unit gain.
    Lens small = model.true_lens;
    small.width = std::max(8, o.width / 8);
    small.height = std::max(8, o.height / 8);
    small.fx /= 8.0;
    small.fy /= 8.0;
    small.cx = (small.cx + 0.5) / 8.0 - 0.5;
    small.cy = (small.cy + 0.5) / 8.0 - 0.5;
    const RayTable rays(small);
    std::vector<double> means(static_cast<size_t>(o.frames));
    cv::Mat radiance;
    for (int f = 0; f < o.frames; ++f) {
      renderRadiance(model.scene, rays, model.pose(f), radiance);
      means[static_cast<size_t>(f)] = model.blank(f) ? imaging.target_mean : cv::mean(radiance)[0];
    }
    model.gains = imaging.gains(means, o.fps);
  } else {
    model.gains.assign(static_cast<size_t>(o.frames), 1.0);
  }
  return model;
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
    // Sub-frames over the exposure, centred on the stamp. The realistic camera takes about one
    // per pixel the view turns during it, at most max_sub_frames; --motion-blur always its 5.
    int subs = 1;
    const double e = imaging.exposure_s;
    if (options.realistic) {
      const Eigen::Isometry3d a = path.pose(t - e / 2), b = path.pose(t + e / 2);
      const double turn_px = Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle() * true_lens.fx;
      subs = std::clamp(static_cast<int>(std::ceil(turn_px)), 1, imaging.max_sub_frames);
    } else if (options.motion_blur) {
      subs = imaging.max_sub_frames;
    }
    cv::Mat sub;
    std::vector<Eigen::Isometry3d> rows(imaging.readout_s > 0 ? static_cast<size_t>(rays.height) : 1);
    for (int k = 0; k < subs; ++k) {
      const double ts = subs > 1 ? t + e * ((k + 0.5) / subs - 0.5) : t;
      // Rolling shutter: row v is exposed readout * (v / (height - 1) - 1/2) after the stamp.
      for (size_t v = 0; v < rows.size(); ++v)
        rows[v] = path.pose(rows.size() == 1 ? ts : ts + imaging.readout_s * (v / (rows.size() - 1.0) - 0.5));
      renderRadiance(scene, rays, rows, sub);
      radiance += sub / subs;
    }
    if (options.exposure_changes && !options.realistic)
      radiance *= 1.0 + 0.25 * std::sin(2 * M_PI * t / 17.0) * std::sin(2 * M_PI * t / 5.3 + 1.0);
  }
  radiance *= gains[static_cast<size_t>(frame)];
  if (imaging.vignetting > 0) radiance = radiance.mul(vignette);
  return imaging.develop(radiance, options.noise, options.seed * 1000003ULL + static_cast<uint64_t>(frame));
}

SequenceSummary writeSequence(const SequenceOptions& o, const fs::path& out,
                              const std::function<void(int, int)>& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  const SequenceModel model = buildSequence(o);
  const RayTable rays(model.true_lens);
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
                         {"realistic", o.realistic},
                         {"exposure_ms", o.exposure_ms},
                         {"readout_ms", o.readout_ms},
                         {"tremor_deg", o.tremor_deg},
                         {"denoise", model.imaging.denoise_sigma},
                         {"lens_error", o.lens_error},
                         {"textures", o.textures.empty() ? "procedural" : o.textures},
                         {"photo_max_look_alikes", photoMaxLookAlikes(o)},
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
    o.realistic = info.value("realistic", false);
    o.exposure_ms = info.value("exposure_ms", -1.0);
    o.readout_ms = info.value("readout_ms", -1.0);
    o.tremor_deg = info.value("tremor_deg", -1.0);
    o.lens_error = info.value("lens_error", true);
    o.denoise = info.value("denoise", 0.0);  // written before: no denoising
    const auto textures = info.at("textures").get<std::string>();
    if (textures != "procedural") o.textures = textures;
    o.photo_max_look_alikes = info.value("photo_max_look_alikes", 1.0);  // written before: every photo
    return o;
  } catch (const nlohmann::json::exception& e) {
    throw InputError(file.string() + ": not what hiveslam synth writes (" + e.what() + ")");
  }
}

}  // namespace hiveslam::synth
