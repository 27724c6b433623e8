#include "distribution/wire/record_codec.hpp"

#include <zstd.h>

#include <algorithm>
#include <cmath>

#include "core/features/orb_extractor.hpp"
#include "distribution/wire/byte_codec.hpp"

namespace hiveslam::distribution {

namespace {

void putPose(ByteWriter& w, const Eigen::Isometry3d& T) {
  const Eigen::Quaterniond q(T.linear());
  for (double x : {q.w(), q.x(), q.y(), q.z()}) w.put(x);
  for (int i = 0; i < 3; ++i) w.put(T.translation()[i]);
}

Eigen::Isometry3d getPose(ByteReader& r) {
  double c[7];
  for (double& x : c) x = r.get<double>();
  Eigen::Quaterniond q(c[0], c[1], c[2], c[3]);
  if (!std::isfinite(q.norm()) || std::abs(q.norm() - 1.0) > 1e-3) throw WireError("bad rotation");
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = q.normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d(c[4], c[5], c[6]);
  if (!T.translation().allFinite()) throw WireError("bad translation");
  return T;
}

void putPoint(ByteWriter& w, const PointRecord& p, uint64_t& previous_id) {
  w.delta(p.id, previous_id);
  for (int i = 0; i < 3; ++i) w.put(static_cast<float>(p.position[i]));
  w.put(static_cast<uint8_t>(p.full));
  if (!p.full) return;
  w.put(p.first_keyframe);
  w.bytes(p.descriptor.data(), 32);
  for (int i = 0; i < 3; ++i) w.put(static_cast<float>(p.normal[i]));
  w.put(static_cast<float>(p.min_distance));
  w.put(static_cast<float>(p.max_distance));
}

PointRecord getPoint(ByteReader& r, uint64_t& previous_id) {
  PointRecord p;
  p.id = r.delta(previous_id);
  for (int i = 0; i < 3; ++i) p.position[i] = r.get<float>();
  if (!p.position.allFinite()) throw WireError("bad point position");
  p.full = r.get<uint8_t>() != 0;
  if (!p.full) return p;
  p.first_keyframe = r.get<Id>();
  r.bytes(p.descriptor.data(), 32);
  for (int i = 0; i < 3; ++i) p.normal[i] = r.get<float>();
  p.min_distance = r.get<float>();
  p.max_distance = r.get<float>();
  if (!p.normal.allFinite() || !std::isfinite(p.min_distance) || !std::isfinite(p.max_distance))
    throw WireError("bad point normal or distances");
  return p;
}

void putIds(ByteWriter& w, const std::vector<Id>& ids) {
  w.put(static_cast<uint32_t>(ids.size()));
  for (Id id : ids) w.put(id);
}

std::vector<Id> getIds(ByteReader& r) {
  std::vector<Id> ids(r.count(8));
  for (Id& id : ids) id = r.get<Id>();
  return ids;
}

void putKeyframe(ByteWriter& w, const KeyFrameRecord& k) {
  w.put(k.id);
  w.put(k.map);
  putPose(w, k.T_cw);
  w.put(static_cast<uint8_t>(k.links || k.full));
  if (k.links || k.full) {
    w.put(k.parent);
    w.put(static_cast<uint32_t>(k.matches.size()));
    uint64_t previous_index = 0, previous_id = 0;
    for (const auto& [i, p] : k.matches) {
      w.delta(i, previous_index);
      w.delta(p, previous_id);
    }
    putIds(w, k.loop_edges);
  }
  w.put(static_cast<uint8_t>(k.full));
  if (!k.full) return;
  const core::Frame& f = k.frame;
  w.put(static_cast<uint64_t>(f.index));
  w.put(f.timestamp);
  for (double x : {f.K.fx, f.K.fy, f.K.cx, f.K.cy}) w.put(x);
  w.put(static_cast<int32_t>(f.width));
  w.put(static_cast<int32_t>(f.height));
  w.put(k.made_in_epoch);
  w.put(k.made_from);
  putPose(w, k.T_made_from);
  w.put(static_cast<uint32_t>(f.keypoints.size()));
  // Per keypoint what the core uses after extraction: image position, angle and pyramid level
  // (matching and scale prediction) with the weak-corner flag in its top bit (triangulation's
  // look-alike check), the undistorted position (geometry) and the descriptor.
  for (size_t i = 0; i < f.keypoints.size(); ++i) {
    const cv::KeyPoint& kp = f.keypoints[i];
    w.put(kp.pt.x);
    w.put(kp.pt.y);
    w.put(kp.angle);
    w.put(static_cast<uint8_t>(kp.octave | (features::isWeakCorner(kp) ? 0x80 : 0)));
    w.put(static_cast<float>(f.points[i].x()));
    w.put(static_cast<float>(f.points[i].y()));
    w.bytes(f.descriptors.ptr<uint8_t>(static_cast<int>(i)), 32);
  }
}

KeyFrameRecord getKeyframe(ByteReader& r) {
  KeyFrameRecord k;
  k.id = r.get<Id>();
  k.map = r.get<Id>();
  k.T_cw = getPose(r);
  k.links = r.get<uint8_t>() != 0;
  if (k.links) {
    k.parent = r.get<Id>();
    k.matches.resize(r.count(2));
    uint64_t previous_index = 0, previous_id = 0;
    for (auto& [i, p] : k.matches) {
      const uint64_t index = r.delta(previous_index);
      if (index > 0xffffffffu) throw WireError("bad keypoint index");
      i = static_cast<uint32_t>(index);
      p = r.delta(previous_id);
    }
    k.loop_edges = getIds(r);
  }
  k.full = r.get<uint8_t>() != 0;
  if (!k.full) return k;
  core::Frame& f = k.frame;
  f.index = r.get<uint64_t>();
  f.timestamp = r.get<double>();
  f.K.fx = r.get<double>();
  f.K.fy = r.get<double>();
  f.K.cx = r.get<double>();
  f.K.cy = r.get<double>();
  f.width = r.get<int32_t>();
  f.height = r.get<int32_t>();
  if (f.width <= 0 || f.height <= 0 || f.width > 100000 || f.height > 100000) throw WireError("bad image size");
  if (!std::isfinite(f.timestamp) || !std::isfinite(f.K.fx) || !std::isfinite(f.K.fy) || !std::isfinite(f.K.cx) ||
      !std::isfinite(f.K.cy) || f.K.fx <= 0 || f.K.fy <= 0)
    throw WireError("bad timestamp or intrinsics");
  k.made_in_epoch = r.get<uint64_t>();
  k.made_from = r.get<Id>();
  k.T_made_from = getPose(r);
  const uint32_t n = r.count(53);
  f.keypoints.resize(n);
  f.points.resize(n);
  f.descriptors = cv::Mat(static_cast<int>(n), 32, CV_8U);
  for (uint32_t i = 0; i < n; ++i) {
    cv::KeyPoint& kp = f.keypoints[i];
    kp.pt.x = r.get<float>();
    kp.pt.y = r.get<float>();
    kp.angle = r.get<float>();
    const auto level = r.get<uint8_t>();
    kp.octave = level & 0x7f;
    kp.class_id = (level & 0x80) ? features::kWeakCorner : -1;
    if (kp.octave > 31) throw WireError("bad keypoint level");
    const float x = r.get<float>(), y = r.get<float>();
    // Not a number, a point would be put in a grid cell by an undefined cast (found by
    // fuzz/wire_fuzzer). A keypoint was detected in the image; its undistorted point may lie
    // outside it (a wide lens), and only has to be a number.
    const bool in_image = kp.pt.x >= -1 && kp.pt.y >= -1 && kp.pt.x <= f.width + 1 && kp.pt.y <= f.height + 1;
    if (!in_image || !std::isfinite(kp.angle) || !std::isfinite(x) || !std::isfinite(y)) throw WireError("bad keypoint");
    f.points[i] = Eigen::Vector2d(x, y);
    r.bytes(f.descriptors.ptr<uint8_t>(static_cast<int>(i)), 32);
  }
  for (const auto& [i, p] : k.matches)
    if (i >= n) throw WireError("match index past the keypoints");
  f.buildGrid();
  return k;
}

}  // namespace

std::vector<uint8_t> encode(const KeyFrameMessage& m) {
  ByteWriter w;
  putKeyframe(w, m.keyframe);
  w.put(static_cast<uint32_t>(m.points.size()));
  uint64_t previous = 0;
  for (const auto& p : m.points) putPoint(w, p, previous);
  w.put(static_cast<uint32_t>(m.companions.size()));
  for (const auto& k : m.companions) putKeyframe(w, k);
  w.put(static_cast<uint32_t>(m.stats.size()));
  uint64_t previous_id = 0;
  for (const auto& s : m.stats) {
    w.delta(s.id, previous_id);
    w.varint(s.visible);
    w.varint(s.found);
  }
  return std::move(w.data());
}

KeyFrameMessage decodeKeyframe(const std::vector<uint8_t>& raw) {
  ByteReader r(raw.data(), raw.size());
  KeyFrameMessage m;
  m.keyframe = getKeyframe(r);
  if (!m.keyframe.full) throw WireError("a new keyframe without its features");
  m.points.resize(r.count(14));
  uint64_t previous = 0;
  for (auto& p : m.points) p = getPoint(r, previous);
  m.companions.resize(r.count(57));
  for (auto& k : m.companions) k = getKeyframe(r);
  m.stats.resize(r.count(3));
  uint64_t previous_id = 0;
  for (auto& s : m.stats) {
    s.id = r.delta(previous_id);
    s.visible = static_cast<uint32_t>(std::min<uint64_t>(r.varint(), 0xffffffffu));
    s.found = static_cast<uint32_t>(std::min<uint64_t>(r.varint(), 0xffffffffu));
  }
  if (!r.done()) throw WireError("trailing bytes");
  return m;
}

std::vector<uint8_t> encode(const MapRecord& m) {
  ByteWriter w;
  w.put(static_cast<uint8_t>(m.kind));
  w.put(m.map);
  w.put(m.epoch);
  w.put(m.batch);
  w.put(m.batches);
  w.put(m.update);
  w.put(m.origin);
  w.put(static_cast<uint32_t>(m.keyframes.size()));
  for (const auto& k : m.keyframes) putKeyframe(w, k);
  w.put(static_cast<uint32_t>(m.points.size()));
  uint64_t previous = 0;
  for (const auto& p : m.points) putPoint(w, p, previous);
  putIds(w, m.erased_keyframes);
  putIds(w, m.erased_points);
  w.put(static_cast<uint32_t>(m.replaced_points.size()));
  for (const auto& [a, b] : m.replaced_points) {
    w.put(a);
    w.put(b);
  }
  putIds(w, m.merged_maps);
  putIds(w, m.mapped);
  return std::move(w.data());
}

MapRecord decodeMap(const std::vector<uint8_t>& raw) {
  ByteReader r(raw.data(), raw.size());
  MapRecord m;
  const auto kind = r.get<uint8_t>();
  if (kind > 1) throw WireError("unknown map kind");
  m.kind = static_cast<MapRecord::Kind>(kind);
  m.map = r.get<Id>();
  m.epoch = r.get<uint64_t>();
  m.batch = r.get<uint32_t>();
  m.batches = r.get<uint32_t>();
  if (m.batches == 0 || m.batch >= m.batches || m.batches > 100000) throw WireError("bad batch numbers");
  m.update = r.get<uint32_t>();
  m.origin = r.get<Id>();
  m.keyframes.resize(r.count(57));
  for (auto& k : m.keyframes) k = getKeyframe(r);
  m.points.resize(r.count(14));
  uint64_t previous = 0;
  for (auto& p : m.points) p = getPoint(r, previous);
  m.erased_keyframes = getIds(r);
  m.erased_points = getIds(r);
  m.replaced_points.resize(r.count(16));
  for (auto& [a, b] : m.replaced_points) {
    a = r.get<Id>();
    b = r.get<Id>();
  }
  m.merged_maps = getIds(r);
  m.mapped = getIds(r);
  if (!r.done()) throw WireError("trailing bytes");
  return m;
}

namespace {

constexpr float kShiftStep = 1.0f / 256.0f;

bool quantize(float shift, int16_t& out) {
  const float q = std::round(shift / kShiftStep);
  if (!(std::abs(q) <= 32767.0f)) return false;  // NaN too
  out = static_cast<int16_t>(q);
  return true;
}

}  // namespace

std::vector<uint8_t> encode(const core::Remeasurements& m) {
  ByteWriter w;
  w.put(static_cast<uint32_t>(m.size()));
  uint64_t previous_keyframe = 0;
  for (const auto& [keyframe, entries] : m) {
    w.delta(keyframe, previous_keyframe);
    // Sorted, each keypoint once, the anchor no later than the keyframe: what decoding checks.
    std::vector<std::pair<const core::Remeasurement*, std::array<int16_t, 2>>> kept;
    for (const auto& e : entries) {
      std::array<int16_t, 2> q{};
      if (!quantize(e.shift.x(), q[0]) || !quantize(e.shift.y(), q[1])) continue;
      if (!kept.empty() && e.keypoint <= kept.back().first->keypoint) continue;
      if (e.point == core::kNoId || e.anchor_keyframe > keyframe) continue;
      kept.emplace_back(&e, q);
    }
    w.put(static_cast<uint32_t>(kept.size()));
    uint32_t previous = 0;
    for (const auto& [e, q] : kept) {
      w.varint(e->keypoint - previous);
      previous = e->keypoint;
      w.put(q[0]);
      w.put(q[1]);
      w.varint(e->point);
      w.varint(keyframe - e->anchor_keyframe);
      w.varint(e->anchor_keypoint);
    }
  }
  return std::move(w.data());
}

core::Remeasurements decodeRemeasurements(const std::vector<uint8_t>& raw) {
  ByteReader r(raw.data(), raw.size());
  core::Remeasurements m;
  const uint32_t keyframes = r.count(5);
  uint64_t previous_keyframe = 0;
  for (uint32_t k = 0; k < keyframes; ++k) {
    const Id keyframe = r.delta(previous_keyframe);
    auto& entries = m[keyframe];
    if (!entries.empty()) throw WireError("a keyframe listed twice");
    entries.resize(r.count(5));
    uint64_t previous = 0;
    for (size_t i = 0; i < entries.size(); ++i) {
      const uint64_t step = r.varint();
      if (i > 0 && step == 0) throw WireError("keypoints out of order");
      previous += step;
      if (previous > 0xffffffffu) throw WireError("keypoint index out of range");
      entries[i].keypoint = static_cast<uint32_t>(previous);
      const auto x = r.get<int16_t>(), y = r.get<int16_t>();
      entries[i].shift = Eigen::Vector2f(x * kShiftStep, y * kShiftStep);
      entries[i].point = r.varint();
      const uint64_t back = r.varint();
      if (back > keyframe) throw WireError("anchor keyframe out of range");
      entries[i].anchor_keyframe = keyframe - back;
      const uint64_t anchor_keypoint = r.varint();
      if (anchor_keypoint > 0xffffffffu) throw WireError("keypoint index out of range");
      entries[i].anchor_keypoint = static_cast<uint32_t>(anchor_keypoint);
    }
  }
  if (!r.done()) throw WireError("trailing bytes");
  return m;
}

std::vector<uint8_t> compress(const std::vector<uint8_t>& raw) {
  std::vector<uint8_t> out(ZSTD_compressBound(raw.size()));
  // Level 1: most of what zstd can take out of descriptors and floats, at the lowest CPU cost.
  // The frame checksum (4 bytes) catches a corrupted body before it is decoded.
  ZSTD_CCtx* ctx = ZSTD_createCCtx();
  ZSTD_CCtx_setParameter(ctx, ZSTD_c_compressionLevel, 1);
  ZSTD_CCtx_setParameter(ctx, ZSTD_c_checksumFlag, 1);
  const size_t n = ZSTD_compress2(ctx, out.data(), out.size(), raw.data(), raw.size());
  ZSTD_freeCCtx(ctx);
  if (ZSTD_isError(n)) throw WireError(std::string("zstd: ") + ZSTD_getErrorName(n));
  out.resize(n);
  return out;
}

std::vector<uint8_t> decompress(const std::vector<uint8_t>& packed, uint32_t raw_size) {
  if (raw_size > (256u << 20)) throw WireError("message too large");
  std::vector<uint8_t> out(raw_size);
  const size_t n = ZSTD_decompress(out.data(), out.size(), packed.data(), packed.size());
  if (ZSTD_isError(n) || n != raw_size) throw WireError("corrupt compressed body");
  return out;
}

}  // namespace hiveslam::distribution
