#pragma once
// Whether a tracking node's link to its mapping node can carry the offloading. Tracking needs
// each keyframe's new points back within a few frames; over a link that takes seconds per
// acknowledgement it runs out of points and loses its map (2 Mbit/s: 4 maps and 5 failures in
// a 240-frame run, acknowledgements 2-50 s). Judged on evidence that only a slow
// link gives: `slow_acks` acknowledgements in a row each later than `slow`; no answer at all
// for `slow_acks` times `slow` while keyframes wait; or tracking lost while a keyframe has
// waited longer than `slow` (over 2 Mbit/s the first map was lost 1.3 s after it began, before
// any acknowledgement). The last two wait out a dead gateway's lease. A keyframe the gateway
// dropped (its map merged meanwhile) never answers: it counts for nothing once a later one
// does, and at a loss only while it is recent.
#include <algorithm>
#include <chrono>
#include <optional>

namespace hiveslam::distribution {

class GatewayWatch {
 public:
  using Clock = std::chrono::steady_clock;
  // `dead_within`: how long a dead gateway can look alive (its lease). Evidence that needs no
  // answer to come (a silence, a loss) must be older than that: a gateway killed mid-run must
  // be taken over (it leaves at its lease), not released.
  GatewayWatch(Clock::duration slow, int slow_acks, Clock::duration dead_within)
      : slow_(slow), slow_acks_(slow_acks), dead_within_(dead_within) {}
  // A keyframe went to the gateway.
  void sent(Clock::time_point t) {
    if (!waiting_since_) waiting_since_ = t;
  }
  // The gateway acknowledged a keyframe sent `round_trip` ago.
  void answered(Clock::duration round_trip) {
    waiting_since_.reset();
    slow_in_a_row_ = round_trip > slow_ ? slow_in_a_row_ + 1 : 0;
  }
  // Another gateway, or none: the next one is judged on its own answers. A keyframe sent to a
  // gateway that died, left waiting, had a restarted LM released as slow the moment it joined.
  void restart() {
    waiting_since_.reset();
    slow_in_a_row_ = 0;
  }
  bool tooSlow(Clock::time_point now) const {
    if (!on()) return false;
    return slow_in_a_row_ >= slow_acks_ ||
           (waiting_since_ && now - *waiting_since_ > std::max<Clock::duration>(slow_ * slow_acks_, dead_within_));
  }
  // Tracking was lost since the last answer: whether the keyframe sent at `sent`, still
  // unanswered, starved it (it has waited longer than `slow` and `dead_within`, and not
  // slow_acks + 2 times `slow` longer still: an old one was dropped, not delayed).
  bool starved(Clock::time_point now, Clock::time_point sent) const {
    const Clock::duration limit = std::max(slow_, dead_within_);
    return on() && now - sent > limit && now - sent <= limit + slow_ * (slow_acks_ + 2);
  }
  int slowInARow() const { return slow_in_a_row_; }

 private:
  bool on() const { return slow_acks_ > 0 && slow_ > Clock::duration::zero(); }
  Clock::duration slow_;
  int slow_acks_;
  Clock::duration dead_within_;
  std::optional<Clock::time_point> waiting_since_;
  int slow_in_a_row_ = 0;
};

}  // namespace hiveslam::distribution
