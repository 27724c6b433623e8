// DdsTransport's life cycle: what a node does while its transport is not up must not touch
// Fast DDS entities that are not there (or are being deleted).
#include "communication/dds/dds_transport.hpp"

#include <gtest/gtest.h>
#include <algorithm>
#include <unistd.h>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/core/status/PublicationMatchedStatus.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TopicDataType.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include <atomic>
#include <cstring>
#include <condition_variable>
#include <mutex>
#include <set>
#include <thread>
#include <vector>

#include "communication/dds/node_announcement.hpp"
#include "hiveslam_msgs/msg/NodeInfoPubSubTypes.h"
#include "hiveslam_msgs/msg/PacketPubSubTypes.h"
#include "eventually.hpp"

namespace hiveslam::communication {
namespace {

// A peer event handled while the node stops re-plans its tasks and subscribes: that reader once
// went into a subscriber being deleted (a TR that never finished). Before start()
// there is no subscriber at all (it crashed).
TEST(DdsTransport, SubscribingBeforeStartOrWhileStoppingIsIgnored) {
  DdsTransport transport({232});  // node tests use 1-229, reader_gate_test 230-231 (232 is the last)
  transport.subscribe(Topic::LmMap, [](Message&&) {});
  PeerInfo self;
  self.node = 9;
  transport.start(self, [](const PeerInfo&, bool) {});
  std::atomic<bool> stopped{false};
  std::thread peer_events([&] {
    while (!stopped)
      for (int t = 0; t < kTopicCount; ++t) transport.subscribe(static_cast<Topic>(t), [](Message&&) {});
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  transport.stop();
  stopped = true;
  peer_events.join();
  transport.subscribe(Topic::LcMap, [](Message&&) {});
  EXPECT_FALSE(transport.peerReads(Topic::LmMap, 1));
}

// A node's announcement carries the peers it has heard (what a tracking node waits for before
// its first frame, distribution/distributed_node.hpp: mutualTasks).
TEST(DdsTransport, AnAnnouncementCarriesThePeersTheNodeHasHeard) {
  // The domain of the test above (Fast DDS has none above 232): its node 9 is ignored here.
  DdsTransport a({232}), b({232});
  PeerInfo self_a, self_b;
  self_a.node = 1;
  self_b.node = 2;
  self_b.seen = {1, 7};
  std::mutex mutex;
  std::condition_variable heard;
  std::vector<uint16_t> seen_by_b;
  bool b_present = false;
  a.start(self_a, [&](const PeerInfo& p, bool present) {
    std::lock_guard lock(mutex);
    if (p.node != 2) return;
    b_present = present;
    seen_by_b = p.seen;
    heard.notify_all();
  });
  b.start(self_b, [](const PeerInfo&, bool) {});
  std::unique_lock lock(mutex);
  ASSERT_TRUE(heard.wait_for(lock, std::chrono::seconds(10), [&] { return b_present; }));
  EXPECT_EQ(seen_by_b, (std::vector<uint16_t>{1, 7}));
  // A change of what it has heard is news, not a repeat.
  self_b.seen = {1};
  lock.unlock();
  b.announce(self_b);
  lock.lock();
  EXPECT_TRUE(heard.wait_for(lock, std::chrono::seconds(10), [&] { return seen_by_b == std::vector<uint16_t>{1}; }));
  lock.unlock();
  b.stop();
  a.stop();
}

// Another process announcing this node's id (two nodes started with one --id) is no peer: its
// announcements are dropped and counted, as every announcement that fails its checks.
TEST(DdsTransport, AnotherProcessWithThisNodesIdIsDroppedAndCounted) {
  DdsTransport a({232}), b({232});
  PeerInfo self_a, self_b;
  self_a.node = self_b.node = 5;
  self_a.incarnation = 1;
  self_b.incarnation = 2;
  std::atomic<int> peers_of_a{0};
  const int dropped_before = droppedAnnouncements();
  a.start(self_a, [&](const PeerInfo&, bool present) { peers_of_a += present; });
  b.start(self_b, [](const PeerInfo&, bool) {});
  EXPECT_TRUE(testing::eventually([&] { return droppedAnnouncements() > dropped_before; }, std::chrono::seconds(10)));
  b.stop();
  a.stop();
  EXPECT_EQ(peers_of_a.load(), 0);
}

// Bytes written under another type's name: what a participant that does not run hiveslam can put
// on a topic.
class RawBytes : public eprosima::fastdds::dds::TopicDataType {
 public:
  explicit RawBytes(const std::string& name) {
    setName(name.c_str());
    m_typeSize = 4096;
    m_isGetKeyDefined = false;
  }
  bool serialize(void* data, eprosima::fastrtps::rtps::SerializedPayload_t* payload) override {
    const auto& bytes = *static_cast<std::vector<uint8_t>*>(data);
    std::memcpy(payload->data, bytes.data(), bytes.size());
    payload->length = static_cast<uint32_t>(bytes.size());
    return true;
  }
  bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t*, void*) override { return false; }
  std::function<uint32_t()> getSerializedSizeProvider(void* data) override {
    return [data] { return static_cast<uint32_t>(static_cast<std::vector<uint8_t>*>(data)->size()); };
  }
  void* createData() override { return new std::vector<uint8_t>(); }
  void deleteData(void* data) override { delete static_cast<std::vector<uint8_t>*>(data); }
  bool getKey(void*, eprosima::fastrtps::rtps::InstanceHandle_t*, bool) override { return false; }
};

// A participant of no hiveslam node on the tests' domain, with one reliable, transient-local
// writer of `type` on `topic_name`: what anyone on the network can write.
class RawWriter {
 public:
  RawWriter(eprosima::fastdds::dds::TopicDataType* type, const std::string& topic_name) : type_(type) {
    namespace dds = eprosima::fastdds::dds;
    participant_ = dds::DomainParticipantFactory::get_instance()->create_participant(232, dds::PARTICIPANT_QOS_DEFAULT);
    if (!participant_) return;
    type_.register_type(participant_);
    dds::Topic* topic = participant_->create_topic(topic_name, type_.get_type_name(), dds::TOPIC_QOS_DEFAULT);
    dds::Publisher* publisher = participant_->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
    dds::DataWriterQos wq = dds::DATAWRITER_QOS_DEFAULT;
    wq.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
    wq.durability().kind = dds::TRANSIENT_LOCAL_DURABILITY_QOS;
    writer_ = publisher->create_datawriter(topic, wq);
  }
  ~RawWriter() {
    if (!participant_) return;
    participant_->delete_contained_entities();
    eprosima::fastdds::dds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
  }
  RawWriter(const RawWriter&) = delete;
  RawWriter& operator=(const RawWriter&) = delete;
  eprosima::fastdds::dds::DataWriter* writer() const { return writer_; }

 private:
  eprosima::fastdds::dds::TypeSupport type_;
  eprosima::fastdds::dds::DomainParticipant* participant_ = nullptr;
  eprosima::fastdds::dds::DataWriter* writer_ = nullptr;
};

// An announcement whose `leaving` byte is 2: Fast CDR throws on such a bool, and the generated
// code let it out of take_next_sample, so one such sample ended every node on the domain
// (std::terminate on the listener thread; fuzz/announcement_fuzzer.cpp found it). It is dropped
// and counted, and the node goes on hearing its peers.
TEST(DdsTransport, AnAnnouncementThatCannotBeReadIsDroppedAndTheNodeGoesOn) {
  namespace dds = eprosima::fastdds::dds;
  // The payload of a valid announcement, and the byte where `leaving` sits.
  hiveslam_msgs::msg::NodeInfoPubSubType node_info;
  auto payloadOf = [&](bool leaving) {
    PeerInfo p;
    p.node = 7;
    p.name = "intruder";
    p.leaving = leaving;
    auto m = toIdl(p);
    eprosima::fastrtps::rtps::SerializedPayload_t payload(node_info.getSerializedSizeProvider(&m)());
    EXPECT_TRUE(node_info.serialize(&m, &payload));
    return std::vector<uint8_t>(payload.data, payload.data + payload.length);
  };
  std::vector<uint8_t> bytes = payloadOf(false);
  const std::vector<uint8_t> leaving = payloadOf(true);
  ASSERT_EQ(bytes.size(), leaving.size());
  size_t at = 0;
  while (at < bytes.size() && bytes[at] == leaving[at]) ++at;
  ASSERT_LT(at, bytes.size());
  bytes[at] = 2;

  DdsTransport a({232}), b({232});
  PeerInfo self_a, self_b;
  self_a.node = 1;
  self_b.node = 2;
  std::atomic<bool> heard_b{false};
  a.start(self_a, [&](const PeerInfo& p, bool present) {
    if (p.node == 2 && present) heard_b = true;
  });
  const int dropped_before = droppedAnnouncements();
  {
    RawWriter raw(new RawBytes(node_info.getName()), "rt/hiveslam/nodes");
    dds::DataWriter* writer = raw.writer();
    ASSERT_NE(writer, nullptr);
    EXPECT_TRUE(testing::eventually(
        [&] {
          writer->write(&bytes);
          return droppedAnnouncements() > dropped_before;
        },
        std::chrono::seconds(10)));
    b.start(self_b, [](const PeerInfo&, bool) {});
    EXPECT_TRUE(testing::eventually([&] { return heard_b.load(); }, std::chrono::seconds(10)));
  }
  b.stop();
  a.stop();
}

// The packet writers keep what they wrote (transient-local, see dds_transport.cpp), yet a
// reader that matches later gets only what is written after it matched, as with volatile
// writers: a node that joins learns the maps from a snapshot, never from old packets.
TEST(DdsTransport, AReaderThatMatchesLateGetsOnlyWhatIsWrittenAfter) {
  DdsTransport a({232}), b({232});
  PeerInfo self_a, self_b;
  self_a.node = 1;
  self_b.node = 2;
  a.start(self_a, [](const PeerInfo&, bool) {});
  // The transport numbers what it writes, from 1: the 4th packet arrives as seq 4.
  const auto packet = [](uint64_t seq) {
    Message m;
    m.source = 1;
    m.body.assign(3000, static_cast<uint8_t>(seq));  // fragmented: over one datagram
    return m;
  };
  for (uint64_t seq = 1; seq <= 3; ++seq) a.publish(Topic::LmMap, packet(seq));
  std::mutex mutex;
  std::condition_variable got;
  std::vector<uint64_t> received;
  b.start(self_b, [](const PeerInfo&, bool) {});
  b.subscribe(Topic::LmMap, [&](Message&& m) {
    std::lock_guard lock(mutex);
    received.push_back(m.seq);
    got.notify_all();
  });
  ASSERT_TRUE(testing::eventually([&] { return a.peerReads(Topic::LmMap, 2); }, std::chrono::seconds(10)));
  a.publish(Topic::LmMap, packet(4));
  std::unique_lock lock(mutex);
  ASSERT_TRUE(got.wait_for(lock, std::chrono::seconds(10), [&] { return !received.empty(); }));
  // Anything older would have come first.
  got.wait_for(lock, std::chrono::milliseconds(300));
  EXPECT_EQ(received, (std::vector<uint64_t>{4}));
  lock.unlock();
  b.stop();
  a.stop();
}

// A teardown that hangs inside Fast DDS (2.9 has lock-order deadlocks there: a TR once never
// ended its run) is left behind once its flush time and margin are over: stop() returns, the
// node's calls after it return at once, and the program knows to end without Fast DDS's exit
// handlers (apps/main.cpp).
TEST(DdsTransport, AStopThatHangsInsideFastDdsIsLeftBehind) {
  std::mutex mutex;
  std::condition_variable released;
  bool release = false;
  DdsOptions options;
  options.domain = 232;
  options.leave_flush_ms = 100;
  options.teardown_margin_ms = 200;
  options.teardown_hook = [&] {
    std::unique_lock lock(mutex);
    released.wait(lock, [&] { return release; });
  };
  DdsTransport transport(options);
  PeerInfo self;
  self.node = 5;
  transport.start(self, [](const PeerInfo&, bool) {});
  const auto start = std::chrono::steady_clock::now();
  transport.stop();
  const auto stopped = std::chrono::steady_clock::now();
  EXPECT_LT(stopped - start, std::chrono::seconds(5));
  EXPECT_GE(stopped - start, std::chrono::milliseconds(300));
  EXPECT_EQ(DdsTransport::teardownsRunning(), 1);
  transport.publish(Topic::LmMap, Message{});
  transport.subscribe(Topic::LcMap, [](Message&&) {});
  transport.unsubscribe(Topic::LcMap);
  EXPECT_FALSE(transport.peerReads(Topic::LmMap, 1));
  transport.stop();  // idempotent
  EXPECT_LT(std::chrono::steady_clock::now() - stopped, std::chrono::seconds(1));
  {
    std::lock_guard lock(mutex);
    release = true;
  }
  released.notify_all();
  EXPECT_TRUE(testing::eventually([] { return DdsTransport::teardownsRunning() == 0; }, std::chrono::seconds(10)));
}

uint64_t refusedOn(const DdsTransport& t, Topic topic) {
  const auto r = t.traffic();
  auto it = r.find(topicName(topic));
  return it == r.end() ? 0 : it->second.messages_refused;
}

// A packet names its source node. One that comes from the participant of another node (a
// process writing into a node's stream under its id) is refused and counted; the node's own
// packets and those of the other node under its own id still go through.
TEST(DdsTransport, APacketNamingAnotherNodeThanItsSenderIsRefused) {
  DdsTransport a({232}), b({232}), c({232});
  PeerInfo sa, sb, sc;
  sa.node = 1;
  sb.node = 2;
  sc.node = 3;
  std::mutex mutex;
  std::set<uint16_t> peers;
  std::vector<uint16_t> got;
  a.start(sa, [&](const PeerInfo& p, bool present) {
    std::lock_guard lock(mutex);
    if (present) peers.insert(p.node);
  });
  b.start(sb, [](const PeerInfo&, bool) {});
  c.start(sc, [](const PeerInfo&, bool) {});
  a.subscribe(Topic::TrKeyframes, [&](Message&& m) {
    std::lock_guard lock(mutex);
    got.push_back(m.source);
  });
  const auto count = [&] {
    std::lock_guard lock(mutex);
    return got.size();
  };
  ASSERT_TRUE(testing::eventually(
      [&] {
        std::lock_guard lock(mutex);
        return peers.count(2) && peers.count(3);
      },
      std::chrono::seconds(10)));
  // A packet may go out before the reader matched (DDS discovery): sent until one is in.
  const auto packet = [](uint16_t source) {
    Message m;
    m.source = source;
    return m;
  };
  ASSERT_TRUE(testing::eventually([&] { return b.peerReads(Topic::TrKeyframes, 1) && c.peerReads(Topic::TrKeyframes, 1); },
                                  std::chrono::seconds(10)));
  b.publish(Topic::TrKeyframes, packet(2));
  ASSERT_TRUE(testing::eventually([&] { return count() == 1; }, std::chrono::seconds(10)));
  c.publish(Topic::TrKeyframes, packet(2));  // node 3 names node 2
  c.publish(Topic::TrKeyframes, packet(3));
  ASSERT_TRUE(testing::eventually([&] { return count() == 2; }, std::chrono::seconds(10)));
  EXPECT_EQ(refusedOn(a, Topic::TrKeyframes), 1u);
  {
    std::lock_guard lock(mutex);
    EXPECT_EQ(got, (std::vector<uint16_t>{2, 3}));
  }
  c.stop();
  b.stop();
  a.stop();
}

// Two processes announce one node id (two devices started with the same --id): the one
// started later is the node, and the other's announcements and packets are refused and
// counted. (A restart looks the same to its peers until the old process's lease ends.)
TEST(DdsTransport, OfTwoProcessesWithOneNodeIdTheLaterIsTheNode) {
  DdsTransport a({232}), older({232}), newer({232});
  PeerInfo sa, so, sn;
  sa.node = 1;
  so.node = sn.node = 2;
  so.incarnation = 10;
  sn.incarnation = 20;
  std::mutex mutex;
  std::vector<uint64_t> incarnations;  // of node 2, as node 1 hears it
  std::vector<uint16_t> got;
  a.start(sa, [&](const PeerInfo& p, bool present) {
    std::lock_guard lock(mutex);
    if (present && p.node == 2) incarnations.push_back(p.incarnation);
  });
  a.subscribe(Topic::TrKeyframes, [&](Message&& m) {
    std::lock_guard lock(mutex);
    got.push_back(m.target);
  });
  const auto heard = [&](uint64_t incarnation) {
    std::lock_guard lock(mutex);
    return std::find(incarnations.begin(), incarnations.end(), incarnation) != incarnations.end();
  };
  // Node 1 hears the older process before the newer one starts, as at a restart. Until node 1
  // has heard both, the older one's packets are taken at their word (its announcement may be
  // still on its way), so the packets below go out only once it has.
  const int dropped_before = droppedAnnouncements();
  older.start(so, [](const PeerInfo&, bool) {});
  ASSERT_TRUE(testing::eventually([&] { return heard(10); }, std::chrono::seconds(10)));
  newer.start(sn, [](const PeerInfo&, bool) {});
  ASSERT_TRUE(testing::eventually([&] { return heard(20); }, std::chrono::seconds(10)));
  ASSERT_TRUE(testing::eventually([&] { return droppedAnnouncements() > dropped_before + 1; }, std::chrono::seconds(10)))
      << "the older process's announcements still heard";
  ASSERT_TRUE(testing::eventually([&] { return older.peerReads(Topic::TrKeyframes, 1) && newer.peerReads(Topic::TrKeyframes, 1); },
                                  std::chrono::seconds(10)));
  Message from_older, from_newer;
  from_older.source = from_newer.source = 2;
  from_older.target = 10;
  from_newer.target = 20;
  older.publish(Topic::TrKeyframes, std::move(from_older));
  newer.publish(Topic::TrKeyframes, std::move(from_newer));
  ASSERT_TRUE(testing::eventually([&] { return refusedOn(a, Topic::TrKeyframes) == 1; }, std::chrono::seconds(10)));
  ASSERT_TRUE(testing::eventually(
      [&] {
        std::lock_guard lock(mutex);
        return !got.empty();
      },
      std::chrono::seconds(10)));
  {
    std::lock_guard lock(mutex);
    EXPECT_EQ(got, std::vector<uint16_t>{20});
    ASSERT_FALSE(incarnations.empty());
    EXPECT_EQ(incarnations.back(), 20u);
  }
  newer.stop();
  older.stop();
  a.stop();
}

// A packet whose sequence number does not go past its writer's last one (the same bytes sent
// again, or an older packet after a newer one) is refused and counted: it would bring back a
// keyframe or a map its writer has moved past.
TEST(DdsTransport, APacketReplayedOrOutOfOrderIsRefused) {
  namespace dds = eprosima::fastdds::dds;
  DdsTransport a({232});
  PeerInfo sa;
  sa.node = 1;
  std::mutex mutex;
  std::vector<uint64_t> got;
  a.start(sa, [](const PeerInfo&, bool) {});
  a.subscribe(Topic::LmMap, [&](Message&& m) {
    std::lock_guard lock(mutex);
    got.push_back(m.seq);
  });
  RawWriter raw(new hiveslam_msgs::msg::PacketPubSubType(), topicName(Topic::LmMap));
  dds::DataWriter* writer = raw.writer();
  ASSERT_NE(writer, nullptr);
  ASSERT_TRUE(testing::eventually(
      [&] {
        dds::PublicationMatchedStatus status;
        writer->get_publication_matched_status(status);
        return status.current_count > 0;
      },
      std::chrono::seconds(10)));
  const auto write = [&](uint64_t seq) {
    hiveslam_msgs::msg::Packet p;
    p.source(9);
    p.seq(seq);
    writer->write(&p);
  };
  const auto count = [&] {
    std::lock_guard lock(mutex);
    return got.size();
  };
  write(5);
  ASSERT_TRUE(testing::eventually([&] { return count() == 1; }, std::chrono::seconds(10)));
  write(5);  // the same again
  write(3);  // an older one
  write(0);  // none
  write(6);
  ASSERT_TRUE(testing::eventually([&] { return count() == 2; }, std::chrono::seconds(10)));
  EXPECT_EQ(refusedOn(a, Topic::LmMap), 3u);
  {
    std::lock_guard lock(mutex);
    EXPECT_EQ(got, (std::vector<uint64_t>{5, 6}));
  }
  a.stop();
}

}  // namespace
}  // namespace hiveslam::communication
