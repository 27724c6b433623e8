#pragma once
// Core objects to records (the caller holds the map's mutex).
#include "core/map/map.hpp"
#include "distribution/wire/records.hpp"

namespace hiveslam::distribution {

KeyFrameRecord captureKeyframe(const core::KeyFrame& kf, Id map, bool full);
PointRecord capturePoint(const core::MapPoint& p, bool full);

}  // namespace hiveslam::distribution
