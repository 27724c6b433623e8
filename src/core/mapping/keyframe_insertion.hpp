#pragma once
// Putting a new keyframe into its map: links it to the map points tracking matched, updates
// their descriptors and viewing ranges, and builds its covisibility. Local mapping does it first
// thing; a tracking node whose local mapping runs on another node does it itself, so that it
// can track against its own keyframes before the remote map update arrives. The caller holds
// the map's mutex.
//
// A keyframe culled before its turn (one that came in a hand-over snapshot, or was taken back,
// while its own job still waited in a queue) stays out: put back, it was alive in this node's
// map only, erased everywhere else and in this node's own S_full.
//
// Nor does a second copy of a keyframe the map holds: a loop-closing node can make one from the
// keyframe's message and one from a snapshot, each before the other was in. Linked, the map's
// points observed the copy, freed with its message. The copy is marked bad, so that whoever
// holds it maps nothing with it.
#include <vector>

#include "core/map/map.hpp"
#include "core/place/keyframe_database.hpp"

namespace hiveslam::core {

void insertKeyframe(Map& map, KeyFrame& kf, const std::vector<double>& scales, KeyframeDatabase* database);

}  // namespace hiveslam::core
