#pragma once
// The distribution layer's numbers (the paper's, as defaults); the `distribution:` section of
// a settings file overrides them.
namespace hiveslam::distribution {

struct DistributionSettings {
  // Local maps: after each mapped keyframe, the keyframes local BA moved are sent newest first
  // in batches that grow from first to max keyframes, batch_gap_ms apart.
  int local_first_batch = 3;
  int local_max_batch = 15;
  int local_batch_gap_ms = 50;
  // A batch that acknowledges a keyframe (its new points, before local BA) goes at once, not
  // after the gap: tracking waits for it, and points its keyframe made are what it tracks next.
  int local_window = 20;  // covisible keyframes of a mapped keyframe counted as changed
  // A point's position goes out again in a local map only when it moved more than this (map
  // units: the first two keyframes set the scale, median depth 1). Global maps send all.
  double min_point_move = 1e-4;
  // A point's full record (descriptor, viewing direction, distance range: what matching uses)
  // goes again only when its descriptor changed in more than point_descriptor_bits bits, its
  // direction turned more than point_normal_deg or its distance range changed by more than
  // point_range_ratio. Sent whenever its observers changed, these records were half of TR's
  // incoming bytes on bigloop.
  int point_descriptor_bits = 10;
  double point_normal_deg = 3.0;
  double point_range_ratio = 0.03;
  // Global maps (loop closure, merge, global BA): the whole map in batches.
  int global_batch = 10;
  int global_batch_gap_ms = 100;
  // LC's global maps to its gateway, on a topic that carries nothing else: no local map waits
  // behind them there, and a merge reaches tracking only after two hops (LC's map to LM, then
  // LM's relay). Paced like the relay, a 7-batch merge took 1.5 s to reach TR on blackout, and
  // TR tracked 230-280 points where the standalone system tracked 345-375.
  int lc_global_batch_gap_ms = 0;
  // How long tracking waits for the gateway to acknowledge its last keyframe as mapped: an
  // offline run waits this long at most before going on; in any run, an acknowledgement this
  // late counts as lost (the keyframe was dropped there) and no longer holds keyframes back.
  int remote_mapping_wait_ms = 2000;
  // A node that takes a task over (a mapping node that joins or returns) gets the maps so far
  // from the node that held them. Up to this long, its keyframes of a map it does not hold yet
  // wait for that map: mapped from nothing, they would start a second copy of it.
  int handover_wait_ms = 10000;
  // A tracking node in real time releases its peers (Control::Release: they leave) and runs
  // the whole system alone once release_slow_acks keyframe acknowledgements in a row took
  // longer than release_slow_gateway_ms each, none came for release_slow_acks times that long,
  // or tracking was lost with a keyframe waiting longer than that (distribution/gateway_watch).
  // 0 in either: never. Loopback acknowledgements take 25-85 ms; over a 2 Mbit/s link they
  // took 2-50 s.
  int release_slow_gateway_ms = 1000;
  int release_slow_acks = 3;
  // How long a dead peer can still look present: the DDS lease (2 s) and its handling. A
  // gateway killed mid-run starves tracking as a slow one does until it is seen to leave.
  int dead_peer_ms = 2500;
};

}  // namespace hiveslam::distribution
