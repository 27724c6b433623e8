#include "distribution/keyframe_subscriber.hpp"

#include <spdlog/spdlog.h>

#include "common/thread_name.hpp"
#include "distribution/packet.hpp"

namespace hiveslam::distribution {

KeyframeSubscriber::KeyframeSubscriber(StateIntegrator& integrator, Route route, OnControl control, AwaitMap await_map,
                                       OnRemeasured remeasured)
    : integrator_(integrator),
      route_(std::move(route)),
      control_(std::move(control)),
      await_map_(std::move(await_map)),
      remeasured_(std::move(remeasured)) {
  thread_ = std::thread([this] {
    nameThisThread("kf-subscriber");
    loop();
  });
}

KeyframeSubscriber::~KeyframeSubscriber() { finish(); }

void KeyframeSubscriber::finish() {
  queue_.close();
  if (thread_.joinable()) thread_.join();
}

void KeyframeSubscriber::loop() {
  while (auto m = queue_.pop()) {
    if (m->kind == static_cast<uint8_t>(PacketKind::Control)) {
      if (control_) control_(*m);
      continue;
    }
    try {
      if (m->kind == static_cast<uint8_t>(PacketKind::Remeasured)) {
        const core::Remeasurements r = decodeRemeasurements(unpack(*m, PacketKind::Remeasured));
        if (remeasured_) remeasured_(r);
        continue;
      }
      const KeyFrameMessage k = decodeKeyframe(unpack(*m, PacketKind::Keyframe));
      ++received_;
      if (k.companions.empty() && await_map_) await_map_(k.keyframe.map, m->target);
      auto added = integrator_.addKeyframe(k, m->epoch);
      if (added.keyframe) route_(added, m->target);
    } catch (const std::exception& e) {
      ++dropped_;
      spdlog::warn("dropped a keyframe-topic message from node {}: {}", m->source, e.what());
    }
  }
}

}  // namespace hiveslam::distribution
