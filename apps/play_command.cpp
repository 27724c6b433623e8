// hiveslam play DATASET: publishes a dataset's frames as a ROS 2 sensor_msgs/msg/Image topic at
// their frame rate, the way the paper fed rosbags to its TR node. Stamps are the dataset's, so
// the TR node's trajectory can be scored against the dataset's ground truth afterwards.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>

#include "apps/commands.hpp"
#include "apps/secure_option.hpp"
#include "common/error.hpp"
#include "communication/dds/image_topic.hpp"
#include "io/open_dataset.hpp"

namespace hiveslam::apps {

namespace {

struct PlayOptions {
  std::string dataset, topic = "/camera/image_raw", frame_id = "camera", config, times;
  int domain = 0;
  double rate = 1.0, wait_seconds = 10.0;
  SecureOption secure;
};

void play(const PlayOptions& o) {
  if (o.rate <= 0) throw InputError("--rate must be positive");
  io::DatasetOptions dataset_options;
  if (!o.config.empty()) dataset_options.settings = o.config;
  if (!o.times.empty()) dataset_options.times = o.times;
  auto source = io::openDataset(o.dataset, dataset_options);
  useSecureOption(o.secure, "play");
  communication::ImageTopicWriter writer(o.domain, o.topic);
  fmt::print(stderr, "{} -> {} on DDS domain {}\n", source->describe(), communication::ddsTopicName(o.topic), o.domain);
  if (o.wait_seconds > 0 &&
      !writer.waitForReaders(1, std::chrono::milliseconds(static_cast<int64_t>(o.wait_seconds * 1000))))
    fmt::print(stderr, "no subscriber after {} s; publishing anyway\n", o.wait_seconds);
  const auto start = std::chrono::steady_clock::now();
  double first = -1;
  size_t n = 0;
  while (auto frame = source->next()) {
    if (first < 0) first = frame->timestamp;
    std::this_thread::sleep_until(start + std::chrono::duration<double>((frame->timestamp - first) / o.rate));
    communication::CameraImage image;
    image.stamp_ns = static_cast<int64_t>(std::llround(frame->timestamp * 1e9));
    image.frame_id = o.frame_id;
    image.width = static_cast<uint32_t>(frame->image.cols);
    image.height = static_cast<uint32_t>(frame->image.rows);
    image.step = image.width;
    image.encoding = "mono8";
    image.data.resize(static_cast<size_t>(image.step) * image.height);
    for (int r = 0; r < frame->image.rows; ++r)
      std::copy_n(frame->image.ptr<uint8_t>(r), image.width, image.data.data() + static_cast<size_t>(r) * image.step);
    writer.write(image);
    ++n;
  }
  // Let the last images leave before the writer goes: its leaving ends the subscribers' stream.
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  fmt::print("published {} frames in {:.1f} s\n", n,
             std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
}

}  // namespace

void addPlayCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("play", "Publish a dataset as a ROS 2 sensor_msgs/msg/Image topic at its frame rate");
  cmd->footer("Example:\n  hiveslam play seq/figure8 --topic /camera/image_raw --domain 7");
  auto o = std::make_shared<PlayOptions>();
  cmd->add_option("DATASET", o->dataset, "What `hiveslam run` reads")->required();
  cmd->add_option("--topic", o->topic, "ROS topic")->capture_default_str();
  cmd->add_option("--domain", o->domain, "DDS domain id (the ROS_DOMAIN_ID)")->capture_default_str();
  cmd->add_option("--rate", o->rate, "Playback speed factor")->capture_default_str();
  cmd->add_option("--wait", o->wait_seconds, "Seconds to wait for a subscriber before the first frame (0: none)")
      ->capture_default_str();
  cmd->add_option("--frame-id", o->frame_id, "header.frame_id")->capture_default_str();
  cmd->add_option("--config", o->config, "Settings YAML (camera section)");
  addSecureOption(cmd, o->secure);
  cmd->add_option("--times", o->times, "Times file for image folders and videos");
  cmd->callback([o]() { play(*o); });
}

}  // namespace hiveslam::apps
