#pragma once
// A whole synthetic sequence: scene, camera motion, imaging effects, written in the EuRoC ASL
// layout (mav0/cam0/{data/,data.csv,sensor.yaml}, mav0/state_groundtruth_estimate0/data.csv)
// with the camera as the body (T_BS = identity) so ground truth is the camera pose.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>

#include "synth/camera_path.hpp"
#include "synth/imaging.hpp"
#include "synth/lens.hpp"
#include "synth/scene.hpp"
#include "synth/trajectory_plan.hpp"

namespace hiveslam::synth {

struct SequenceOptions {
  std::string trajectory = "loop";
  uint64_t seed = 1;
  int frames = 1000;
  int width = 752, height = 480;
  double fps = 20.0;
  std::string textures;          // folder of photos; empty: procedural textures
  bool distortion = false;       // EuRoC-like radial-tangential lens
  double noise = 2.0;            // sensor noise sigma, grey levels
  bool motion_blur = false;      // average of sub-frames over a 10 ms exposure
  bool exposure_changes = false; // slow gain changes of up to +-25%
  // Made to look like a hand-held consumer camera in a lived-in room (synth/imaging.hpp,
  // synth/furnished_room.hpp): a furnished room lit by lamps, a 62-degree lens that differs from
  // the nominal one in sensor.yaml, motion blur of a 20 ms exposure, rolling shutter, auto
  // exposure, vignetting, shot noise, denoising and JPEG. Implies motion_blur; replaces exposure_changes.
  bool realistic = false;
  // Ablations of the realistic camera (negative: Imaging::realistic()'s value).
  double exposure_ms = -1, readout_ms = -1, tremor_deg = -1;
  double denoise = -1;           // the camera's denoising, grey levels (Imaging::denoise_sigma)
  bool lens_error = true;        // false: the true lens is the nominal one
  // Photos that repeat themselves more than this are not used as textures (loadPhotos).
  // Negative: realistic renders keep photos up to 0.35, the look-alike share of the most
  // repetitive tenth of real frames (phone_room_droidcam's keyboard; KITTI's median frame is at
  // 0.05), and the others keep every photo.
  double photo_max_look_alikes = -1;
  int threads = 0;               // 0: all cores
};

// Everything a sequence is made of, rebuilt deterministically from the options.
struct SequenceModel {
  SequenceOptions options;
  Lens lens;       // the nominal camera, as sensor.yaml says
  Lens true_lens;  // the one the images are made with: `lens` unless realistic
  Scene scene;
  CameraPath path;
  TrajectoryPlan plan;
  Imaging imaging;
  std::vector<double> gains;  // per frame: auto exposure (all 1 without it)
  cv::Mat vignette;           // per pixel brightness factor

  double stamp(int frame) const;                   // seconds
  int64_t stampNs(int frame) const;
  Eigen::Isometry3d pose(int frame) const;         // T_wc at the frame's stamp
  bool blank(int frame) const;
  // The 8-bit image of a frame with every imaging effect applied; `rays` of true_lens.
  cv::Mat renderImage(int frame, const RayTable& rays) const;
};

SequenceModel buildSequence(const SequenceOptions& options);

// The options a sequence written by writeSequence was made with, from its `sequence.json`: with
// them buildSequence rebuilds its scene and path exactly (the oracle of evaluations that need
// more than the ground-truth poses). InputError where the file is missing or malformed.
SequenceOptions readSequenceOptions(const std::filesystem::path& dataset);

struct SequenceSummary {
  int frames = 0, blank_frames = 0;
  double path_length = 0.0, duration = 0.0, render_seconds = 0.0;
};

// Renders every frame (frames in parallel) and writes the dataset under `out`.
SequenceSummary writeSequence(const SequenceOptions& options, const std::filesystem::path& out,
                              const std::function<void(int done, int total)>& progress = {});

}  // namespace hiveslam::synth
