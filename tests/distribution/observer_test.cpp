// The Observer collects a global map's batches until the last one is in. Batches of one map
// can come from two senders at once: a mapping node that joins gets TR's hand-over on the map
// topic while LC's next update of the same map arrives on LC's. Each sender counts its own
// epochs, so neither update may drop the other's batches as those of an older one.
#include <gtest/gtest.h>

#include "distribution/observer.hpp"

namespace hiveslam::distribution {
namespace {

MapRecord batch(uint64_t epoch, uint32_t i, uint32_t n, uint32_t update = 0) {
  MapRecord m;
  m.kind = MapRecord::Kind::Global;
  m.map = 7;
  m.epoch = epoch;
  m.batch = i;
  m.batches = n;
  m.update = update;
  return m;
}

TEST(ObserverGlobals, TwoSendersUpdatesOfOneMapAreCollectedApart) {
  Observer o;
  constexpr uint16_t kTr = 1, kLc = 3;
  EXPECT_FALSE(o.collectGlobal(batch(3, 0, 3), kTr));
  EXPECT_FALSE(o.collectGlobal(batch(4, 1, 2), kLc));  // LC's first batch went before this node listened
  EXPECT_FALSE(o.collectGlobal(batch(3, 1, 3), kTr));
  const auto all = o.collectGlobal(batch(3, 2, 3), kTr);
  ASSERT_TRUE(all);
  EXPECT_EQ(all->size(), 3u);
  EXPECT_EQ(all->front().epoch, 3u);
}

TEST(ObserverGlobals, ANewerUpdateFromTheSameSenderDropsAnUnfinishedOlderOne) {
  Observer o;
  EXPECT_FALSE(o.collectGlobal(batch(1, 0, 2), 3));
  EXPECT_FALSE(o.collectGlobal(batch(2, 0, 2), 3));
  EXPECT_FALSE(o.collectGlobal(batch(1, 1, 2), 3));  // a late batch of the dropped update
  const auto all = o.collectGlobal(batch(2, 1, 2), 3);
  ASSERT_TRUE(all);
  EXPECT_EQ(all->front().epoch, 2u);
}

// A loop-closing node that returns joins while the gateway, which closed loops in its absence,
// sends a periodic global map; the newcomer's snapshot follows with the same epoch label and
// the same number of batches. Collected by label, the first map's last batch completed the
// snapshot in its place: the returning node never made the snapshot's last keyframes and ended
// the run without them (3 of 11 runs).
TEST(ObserverGlobals, TwoUpdatesWithOneLabelAreCollectedApart) {
  Observer o;
  constexpr uint16_t kLm = 2;
  auto snapshot = [](uint32_t i) {
    MapRecord m = batch(8, i, 3, /*update=*/6);
    m.keyframes.emplace_back().full = true;
    return m;
  };
  EXPECT_FALSE(o.collectGlobal(batch(8, 2, 3, /*update=*/5), kLm));  // the periodic map's last batch
  EXPECT_FALSE(o.collectGlobal(snapshot(0), kLm));
  EXPECT_FALSE(o.collectGlobal(snapshot(1), kLm));
  const auto all = o.collectGlobal(snapshot(2), kLm);
  ASSERT_TRUE(all);
  ASSERT_EQ(all->size(), 3u);
  for (const auto& b : *all) {
    EXPECT_EQ(b.update, 6u);
    ASSERT_EQ(b.keyframes.size(), 1u);
    EXPECT_TRUE(b.keyframes.front().full);
  }
}

// A sender that dies halfway through a global map never finishes it; when it leaves (or comes
// back as a new incarnation that numbers its updates afresh) its half is dropped, and another
// sender's collection of the same map is kept.
TEST(ObserverGlobals, ASenderThatLeavesTakesItsUnfinishedGlobalMapWithIt) {
  Observer o;
  constexpr uint16_t kLm = 2, kLc = 3;
  EXPECT_FALSE(o.collectGlobal(batch(9, 0, 3, /*update=*/4), kLm));
  EXPECT_FALSE(o.collectGlobal(batch(9, 1, 3, /*update=*/4), kLm));
  EXPECT_FALSE(o.collectGlobal(batch(5, 0, 2, /*update=*/1), kLc));
  EXPECT_EQ(o.dropPendingGlobals(kLm), 2u);
  EXPECT_EQ(o.dropPendingGlobals(kLm), 0u);
  // The returning LM's first update, of an epoch below the dead one's, is collected whole.
  EXPECT_FALSE(o.collectGlobal(batch(2, 0, 2, /*update=*/1), kLm));
  const auto lm = o.collectGlobal(batch(2, 1, 2, /*update=*/1), kLm);
  ASSERT_TRUE(lm);
  EXPECT_EQ(lm->size(), 2u);
  const auto lc = o.collectGlobal(batch(5, 1, 2, /*update=*/1), kLc);
  ASSERT_TRUE(lc);
  EXPECT_EQ(lc->front().epoch, 5u);
}

// TR queued a keyframe of map 7 and published it after LC's merge of 7 into 8 had reached it:
// S_full files the record under map 8, so the next snapshot of 8 that lacks it (LM culled it)
// prunes it. Filed under 7, it stayed in TR's S_full after its map had culled it.
TEST(ObserverMerges, ARecordNamingAMergedMapBelongsToTheMapItWentInto) {
  Observer o;
  MapRecord merge;
  merge.kind = MapRecord::Kind::Global;
  merge.map = 8;
  merge.merged_maps = {7};
  o.record(merge);
  KeyFrameRecord late;
  late.id = 40;
  late.map = 7;
  o.record(late);
  PointRecord p;
  p.id = 41;
  p.full = true;
  o.record(p, 7);
  ASSERT_EQ(o.keyframeCount(), 1u);
  MapRecord snapshot;
  snapshot.kind = MapRecord::Kind::Global;
  snapshot.map = 8;
  const auto known = [](Id) { return true; };
  o.prune(snapshot, {}, {}, known, known);
  EXPECT_EQ(o.keyframeCount(), 0u);
  EXPECT_FALSE(o.hasPoint(41));
}

}  // namespace
}  // namespace hiveslam::distribution
