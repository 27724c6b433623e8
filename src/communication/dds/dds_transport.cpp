#include "communication/dds/dds_transport.hpp"

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <fastdds/rtps/common/InstanceHandle.h>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>

#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <future>
#include <map>
#include <mutex>
#include <thread>
#include <utility>
#include <unordered_map>

#include "common/blocking_queue.hpp"
#include "common/error.hpp"
#include "common/thread_name.hpp"
#include "communication/dds/checked_type.hpp"
#include "communication/dds/node_announcement.hpp"
#include "communication/dds/participant_security.hpp"
#include "hiveslam_msgs/msg/NodeInfoPubSubTypes.h"
#include "hiveslam_msgs/msg/PacketPubSubTypes.h"

namespace hiveslam::communication {

namespace dds = eprosima::fastdds::dds;
using eprosima::fastrtps::Duration_t;
using eprosima::fastrtps::rtps::GuidPrefix_t;
using eprosima::fastrtps::rtps::ParticipantDiscoveryInfo;

namespace {

constexpr const char* kNodeTopic = "rt/hiveslam/nodes";

}  // namespace

struct DdsTransport::Impl : public dds::DomainParticipantListener {
  DdsOptions options;
  dds::DomainParticipant* participant = nullptr;
  dds::Publisher* publisher = nullptr;
  dds::Subscriber* subscriber = nullptr;
  dds::TypeSupport packet_type{new CheckedType<hiveslam_msgs::msg::PacketPubSubType>()};
  dds::TypeSupport node_type{new CheckedType<hiveslam_msgs::msg::NodeInfoPubSubType, noteDroppedAnnouncement>()};
  std::array<dds::Topic*, kTopicCount> topics{};
  dds::Topic* node_topic = nullptr;
  dds::DataWriter* node_writer = nullptr;
  dds::DataReader* node_reader = nullptr;

  // Two locks, never held together with a Fast DDS call that may call back: `entities` for
  // making and deleting writers and readers (listeners never take it), `mutex` for the peer
  // table and this node's announcement (listeners take it).
  std::mutex entities;
  bool closed = true;  // no participant (before start, after stop)
  // Set as stop() begins, read without `entities`: what is published, subscribed or asked for
  // from then on never waits for the teardown (which may hold `entities` long, or for good).
  std::atomic<bool> stopping{false};
  std::array<dds::DataWriter*, kTopicCount> writers{};
  std::array<uint64_t, kTopicCount> next_seq{};  // the last sequence number written, by topic; under `entities`
  // Topics this node's permissions do not let it write (a secure domain): asked once.
  std::array<bool, kTopicCount> denied{};
  struct Reader;
  std::array<std::unique_ptr<Reader>, kTopicCount> readers;
  std::mutex mutex;  // guards everything below
  PeerInfo self;
  PeerHandler on_peer;
  // Which participant each peer announced itself from: a participant lost means that node left.
  std::unordered_map<uint16_t, std::pair<GuidPrefix_t, PeerInfo>> peers;
  // The node each participant announced itself as, kept past its leaving notice (its last
  // packets, a Done among them, may come after it) until the participant is gone; and the
  // participants whose node id a newer incarnation took. Packets are judged by them (admits()).
  std::map<GuidPrefix_t, uint16_t> announced_as;
  std::map<GuidPrefix_t, bool> superseded;  // true once its refused announcement was logged
  std::map<eprosima::fastrtps::rtps::GUID_t, uint64_t> last_seq;  // by writer
  TrafficCounter counter;
  bool running = false;
  std::thread heartbeat;
  // Peer events go to the handler from their own thread, never from a Fast DDS listener: the
  // handler subscribes and unsubscribes, which must not happen inside a listener callback.
  BlockingQueue<std::pair<PeerInfo, bool>> peer_events;
  std::thread peer_thread;
  std::condition_variable wake;
  std::atomic<uint16_t> self_node{0};  // set before any reader exists
  std::atomic<uint64_t> self_incarnation{0};

  // The participants whose readers each writer has matched, for peerReads. Own lock: the
  // listener runs on Fast DDS threads, also inside create_datawriter.
  struct WriterListener : public dds::DataWriterListener {
    Impl* impl = nullptr;
    size_t topic = 0;
    void on_publication_matched(dds::DataWriter*, const dds::PublicationMatchedStatus& info) override {
      const GuidPrefix_t prefix = eprosima::fastrtps::rtps::iHandle2GUID(info.last_subscription_handle).guidPrefix;
      std::lock_guard lock(impl->match_mutex);
      int& readers = impl->matched[topic][prefix];
      readers += info.current_count_change;
      if (readers <= 0) impl->matched[topic].erase(prefix);
    }
  };
  std::array<WriterListener, kTopicCount> writer_listeners;
  std::mutex match_mutex;
  std::array<std::map<GuidPrefix_t, int>, kTopicCount> matched;

  // Delivers a topic's packets to its handler as they arrive (on a Fast DDS thread).
  struct Reader : public dds::DataReaderListener {
    Impl* impl = nullptr;
    Topic topic{};
    Handler handler;
    dds::DataReader* reader = nullptr;
    void on_data_available(dds::DataReader* r) override {
      hiveslam_msgs::msg::Packet p;
      dds::SampleInfo info;
      while (r->take_next_sample(&p, &info) == ReturnCode_t::RETCODE_OK) {
        // A reader also matches its own participant's writer of the topic (the gateway reads
        // the map topic it publishes, for a hand-over): its own packets are not news to it.
        if (!info.valid_data || p.source() == impl->self_node.load()) continue;
        std::string why;
        if (!impl->admits(p.source(), p.seq(), info.sample_identity.writer_guid(), why)) {
          const uint64_t n = impl->counter.refused(topic);
          if ((n & (n - 1)) == 0)  // the 1st, 2nd, 4th, 8th...: a flood does not flood the log
            spdlog::warn("node {}: refused a packet on {} ({} so far): {}", impl->self_node.load(), topicName(topic), n, why);
          continue;
        }
        Message m;
        m.version = p.version();
        m.source = p.source();
        m.kind = p.kind();
        m.target = p.target();
        m.seq = p.seq();
        m.map = p.map_id();
        m.epoch = p.epoch();
        m.raw_size = p.raw_size();
        m.body = std::move(p.body());
        impl->counter.received(topic, m.wireSize());
        spdlog::debug("node {}: in  {} kind {} from {} map {} seq {} {} B", impl->self_node.load(), topicName(topic), m.kind,
                      m.source, m.map, m.seq, m.wireSize());
        handler(std::move(m));
      }
    }
    // The writer no longer held packets this reader had not acknowledged (keep-last history):
    // whatever they carried reaches this node only with a later snapshot.
    void on_sample_lost(dds::DataReader*, const dds::SampleLostStatus& status) override {
      impl->counter.lost(topic, static_cast<uint64_t>(status.total_count_change));
      spdlog::warn("node {}: {} packets lost on {}", impl->self_node.load(), status.total_count_change, topicName(topic));
    }
  };

  // Peer announcements.
  struct NodeListener : public dds::DataReaderListener {
    Impl* impl = nullptr;
    void on_data_available(dds::DataReader* r) override {
      hiveslam_msgs::msg::NodeInfo m;
      dds::SampleInfo info;
      while (r->take_next_sample(&m, &info) == ReturnCode_t::RETCODE_OK) {
        if (!info.valid_data) continue;
        std::string why;
        const auto p = fromIdl(m, why);
        // Two nodes with one id would make colliding keyframe and point ids.
        if (p && p->node == impl->self_node.load() && p->incarnation != impl->self_incarnation.load())
          why = "another process announces this node's id " + std::to_string(p->node) + " (give each node its own --id)";
        if (!why.empty()) {
          noteDroppedAnnouncement();
          spdlog::warn("node {}: dropped an announcement: {}", impl->self_node.load(), why);
          continue;
        }
        impl->peerSeen(*p, info.sample_identity.writer_guid().guidPrefix);
      }
    }
  } node_listener;

  // A packet names its source node. It is refused when it comes from a participant that
  // announced itself as another node, or as this one in an incarnation a newer one replaced (a
  // second process with the node's id), or when its sequence number does not go past the last
  // one of its writer (replayed, or out of order). A participant not yet heard announcing is
  // taken at its word: its first packets may come before its announcement, at the start and
  // at a restart. Strangers are kept out by DDS Security (--secure), not here.
  bool admits(uint16_t source, uint64_t seq, const eprosima::fastrtps::rtps::GUID_t& writer, std::string& why) {
    std::lock_guard lock(mutex);
    if (superseded.count(writer.guidPrefix)) {
      why = "from a process whose node id " + std::to_string(source) + " a newer process took";
      return false;
    }
    if (auto a = announced_as.find(writer.guidPrefix); a != announced_as.end() && a->second != source) {
      why = "it names node " + std::to_string(source) + " but comes from node " + std::to_string(a->second);
      return false;
    }
    uint64_t& last = last_seq[writer];
    if (seq <= last) {
      why = "sequence number " + std::to_string(seq) + " after " + std::to_string(last) + " (replayed or out of order)";
      return false;
    }
    last = seq;
    return true;
  }

  void peerSeen(const PeerInfo& p, const GuidPrefix_t& prefix) {
    bool refused = false, first = false;
    {
      std::lock_guard lock(mutex);
      if (!running || p.node == self.node) return;
      if (auto s = superseded.find(prefix); s != superseded.end()) {
        refused = true;
        first = !std::exchange(s->second, true);
      } else if (auto it = peers.find(p.node); it != peers.end() && it->second.first != prefix) {
        // Two participants announce one node id. The newer incarnation is the node (a restart
        // announces before the old participant's lease ends); the other is refused from then on,
        // its announcements and its packets.
        if (it->second.second.incarnation > p.incarnation) {
          refused = first = true;
          superseded[prefix] = true;
        } else {
          superseded.emplace(it->second.first, false);
        }
      }
      if (!refused) {
        announced_as[prefix] = p.node;
        if (p.leaving) {
          if (!peers.erase(p.node)) return;
        } else {
          auto it = peers.find(p.node);
          const bool same = it != peers.end() && it->second.second.incarnation == p.incarnation &&
                            it->second.second.hosted == p.hosted && it->second.second.seen == p.seen;
          peers[p.node] = {prefix, p};
          if (same) return;  // a heartbeat: nothing new
        }
      }
    }
    if (refused) {
      noteDroppedAnnouncement();
      if (first)
        spdlog::warn("node {}: dropped an announcement: two processes announce node {}; the one started later is the node",
                     self_node.load(), p.node);
      return;
    }
    peer_events.push({p, !p.leaving});
  }

  // A remote participant that could not prove an identity of this domain's CA (no keys, other
  // keys): never matched, counted for the report.
  void onParticipantAuthentication(dds::DomainParticipant*, eprosima::fastrtps::rtps::ParticipantAuthenticationInfo&& info) override {
    if (info.status != eprosima::fastrtps::rtps::ParticipantAuthenticationInfo::UNAUTHORIZED_PARTICIPANT) return;
    noteFailedHandshake();
    spdlog::warn("node {}: a participant failed DDS authentication and is ignored", self_node.load());
  }

  void on_participant_discovery(dds::DomainParticipant*, ParticipantDiscoveryInfo&& info) override {
    if (info.status != ParticipantDiscoveryInfo::REMOVED_PARTICIPANT &&
        info.status != ParticipantDiscoveryInfo::DROPPED_PARTICIPANT)
      return;
    std::lock_guard lock(mutex);
    const GuidPrefix_t gone = info.info.m_guid.guidPrefix;
    announced_as.erase(gone);
    superseded.erase(gone);
    std::erase_if(last_seq, [&](const auto& w) { return w.first.guidPrefix == gone; });
    for (auto it = peers.begin(); it != peers.end();) {
      if (it->second.first == info.info.m_guid.guidPrefix) {
        peer_events.push({it->second.second, false});
        it = peers.erase(it);
      } else {
        ++it;
      }
    }
  }

  dds::DataWriter* writerFor(Topic t) {
    auto& w = writers[static_cast<size_t>(t)];
    if (w || denied[static_cast<size_t>(t)]) return w;
    if (!mayWrite(topicName(t))) {
      // The node's grant leaves this topic out: what it would write there is dropped and
      // counted as failed writes, as a peer would drop it (security/grants.hpp).
      denied[static_cast<size_t>(t)] = true;
      spdlog::info("DDS: this node's permissions leave out writing {}", topicName(t));
      return nullptr;
    }
    const ScopedThreadName name("fastdds");
    dds::DataWriterQos q = dds::DATAWRITER_QOS_DEFAULT;
    q.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
    q.reliability().max_blocking_time = Duration_t(0, 50'000'000);
    q.history().kind = dds::KEEP_LAST_HISTORY_QOS;  // a dead reader can not stall the writer
    q.history().depth = options.history_depth;
    // Transient-local, though the readers are volatile (they get only what is written after
    // they matched, as from a volatile writer). A volatile writer erases each packet once every
    // reader has it, and Fast DDS 2.9 does that erasing, when a reader leaves with packets
    // outstanding, under a lock its asynchronous sender takes in the other order: a TR that
    // released its peers over a slow link deadlocked in 1 of 4 runs (eProsima/Fast-DDS#3468,
    // fixed after 2.9). A transient-local writer erases only what its history depth pushes out.
    q.durability().kind = dds::TRANSIENT_LOCAL_DURABILITY_QOS;
    q.publish_mode().kind = dds::ASYNCHRONOUS_PUBLISH_MODE;  // large packets are sent off-thread
    q.reliable_writer_qos().times.heartbeatPeriod = Duration_t(options.heartbeat_ms / 1000.0);
    auto& listener = writer_listeners[static_cast<size_t>(t)];
    listener.impl = this;
    listener.topic = static_cast<size_t>(t);
    w = publisher->create_datawriter(topics[static_cast<size_t>(t)], q, &listener);
    if (!w) throw InputError(std::string("DDS: cannot create a writer for ") + topicName(t));
    return w;
  }

  // stop()'s part inside Fast DDS: the last packets flushed, the leaving notice, the entities
  // and the participant deleted.
  void teardown(const PeerInfo& last);
  void dropReader(Topic topic);

  // Writes happen outside `mutex`: Fast DDS delivers to a reader of the same participant on
  // the writing thread, and that reader's listener takes `mutex`.
  void write(const PeerInfo& p) {
    auto m = toIdl(p);
    std::lock_guard lock(write_mutex);
    node_writer->write(&m);
  }
  std::mutex write_mutex;
};

DdsTransport::DdsTransport(DdsOptions options) : impl_(std::make_shared<Impl>()) { impl_->options = std::move(options); }

DdsTransport::~DdsTransport() { stop(); }

void DdsTransport::start(const PeerInfo& self, PeerHandler on_peer) {
  Impl& d = *impl_;
  const ScopedThreadName name("fastdds");
  dds::DomainParticipantQos pq = dds::PARTICIPANT_QOS_DEFAULT;
  pq.name(self.name.empty() ? "hiveslam" : self.name);
  auto& discovery = pq.wire_protocol().builtin.discovery_config;
  // A dead node is noticed within ~2 s; announcements at start-up come every 100 ms so that
  // peers match in well under a second (shared/notes: the default can take 3 s).
  discovery.leaseDuration = Duration_t(2, 0);
  discovery.leaseDuration_announcementperiod = Duration_t(0, 500'000'000);
  discovery.initial_announcements.count = 5;
  discovery.initial_announcements.period = Duration_t(0, 100'000'000);
  // UDP only, no shared memory. A node killed and started again on the same host can take its
  // old participant's shared-memory port; Fast DDS 2.9 then removes the dead port's segment
  // while the peers still write into it, and neither side ever matches the other (a returning LC saw no peer for 24 s, 1 restart in about 30; upstream eProsima/Fast-DDS
  // PR 4728, after 2.9). Nodes on separate devices talk UDP anyway, and a node sends a few
  // Mbps at most.
  pq.transport().use_builtin_transports = false;
  auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
  udp->maxMessageSize = static_cast<uint32_t>(d.options.max_datagram_bytes);  // secure: see applySecurity
  pq.transport().user_transports.push_back(udp);
  applySecurity(pq);
  d.participant = dds::DomainParticipantFactory::get_instance()->create_participant(
      static_cast<dds::DomainId_t>(d.options.domain), pq, &d, dds::StatusMask::none());
  if (!d.participant) throw InputError("DDS: cannot create a participant on domain " + std::to_string(d.options.domain));
  d.packet_type.register_type(d.participant);
  d.node_type.register_type(d.participant);
  d.publisher = d.participant->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
  d.subscriber = d.participant->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
  for (int i = 0; i < kTopicCount; ++i)
    d.topics[static_cast<size_t>(i)] = d.participant->create_topic(topicName(static_cast<Topic>(i)),
                                                                   d.packet_type.get_type_name(), dds::TOPIC_QOS_DEFAULT);
  d.node_topic = d.participant->create_topic(kNodeTopic, d.node_type.get_type_name(), dds::TOPIC_QOS_DEFAULT);
  dds::DataWriterQos wq = dds::DATAWRITER_QOS_DEFAULT;
  wq.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
  wq.durability().kind = dds::TRANSIENT_LOCAL_DURABILITY_QOS;  // late joiners see who is there
  wq.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  wq.history().depth = 1;
  d.node_writer = d.publisher->create_datawriter(d.node_topic, wq);
  dds::DataReaderQos rq = dds::DATAREADER_QOS_DEFAULT;
  rq.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
  rq.durability().kind = dds::TRANSIENT_LOCAL_DURABILITY_QOS;
  rq.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  rq.history().depth = 8;
  d.node_listener.impl = &d;
  {
    std::lock_guard lock(d.entities);
    d.closed = false;
    // Every topic's writer now, before any peer is heard of: its readers match during
    // discovery. Made at its first write instead, a writer sent that packet to no one (a
    // mapping node that returned mid-run forwarded TR's new map to LC that way, and LC never
    // got the map; CI).
    for (int i = 0; i < kTopicCount; ++i) d.writerFor(static_cast<Topic>(i));
  }
  d.self_node = self.node;
  d.self_incarnation = self.incarnation;
  {
    std::lock_guard lock(d.mutex);
    d.self = self;
    d.on_peer = std::move(on_peer);
    d.running = true;
  }
  d.peer_thread = std::thread([&d] {
    nameThisThread("dds-peers");
    while (auto e = d.peer_events.pop())
      if (d.on_peer) d.on_peer(e->first, e->second);
  });
  d.write(self);
  d.node_reader = d.subscriber->create_datareader(d.node_topic, rq, &d.node_listener);
  if (!d.node_writer || !d.node_reader) throw InputError("DDS: cannot create the discovery topic");
  // Announcements repeat once a second: the load changes, and a peer that missed one catches up.
  d.heartbeat = std::thread([&d] {
    nameThisThread("dds-heartbeat");
    std::unique_lock lock(d.mutex);
    while (d.running) {
      d.wake.wait_for(lock, std::chrono::seconds(1));
      if (!d.running) break;
      const PeerInfo p = d.self;
      lock.unlock();
      d.write(p);
      lock.lock();
    }
  });
}

void DdsTransport::announce(const PeerInfo& self) {
  {
    std::lock_guard lock(impl_->mutex);
    impl_->self = self;
    if (!impl_->running) return;
  }
  impl_->write(self);
}

void DdsTransport::publish(Topic topic, Message&& m) {
  Impl& d = *impl_;
  if (d.stopping) return;
  hiveslam_msgs::msg::Packet p;
  p.version(m.version);
  p.source(m.source);
  p.kind(m.kind);
  p.target(m.target);
  p.map_id(m.map);
  p.epoch(m.epoch);
  p.raw_size(m.raw_size);
  const size_t bytes = m.wireSize();
  p.body(std::move(m.body));
  // Held through the write: stop() deletes the writers under it.
  std::lock_guard lock(d.entities);
  if (d.closed) return;
  dds::DataWriter* writer = d.writerFor(topic);
  // Numbered under the lock that orders the writes: a reader refuses one that goes back.
  p.seq(++d.next_seq[static_cast<size_t>(topic)]);
  if (writer && writer->write(&p)) {
    d.counter.sent(topic, bytes);
    spdlog::debug("node {}: out {} kind {} map {} seq {} {} B", d.self_node.load(), topicName(topic), p.kind(), p.map_id(),
                  p.seq(), bytes);
  } else {
    d.counter.writeFailed(topic);
    if (writer) spdlog::warn("node {}: a write on {} failed ({} bytes)", d.self_node.load(), topicName(topic), bytes);
  }
}

void DdsTransport::subscribe(Topic topic, Handler handler) {
  Impl& d = *impl_;
  if (d.stopping) return;
  std::lock_guard lock(d.entities);
  // Stopping (or not started): a peer event handled during stop() subscribes as the node takes
  // a task back, and a reader made then went into a subscriber being deleted (a TR
  // once never finished when the returning LM left at the very end of the run).
  if (d.closed) return;
  auto& r = d.readers[static_cast<size_t>(topic)];
  if (r) return;  // one handler per topic for the life of the reader
  if (!mayRead(topicName(topic))) {
    spdlog::warn("DDS: this node's permissions do not allow reading {}", topicName(topic));
    return;
  }
  r = std::make_unique<Impl::Reader>();
  r->impl = &d;
  r->topic = topic;
  r->handler = std::move(handler);
  const ScopedThreadName name("fastdds");
  dds::DataReaderQos q = dds::DATAREADER_QOS_DEFAULT;
  q.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
  q.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  q.history().depth = d.options.history_depth;
  r->reader = d.subscriber->create_datareader(d.topics[static_cast<size_t>(topic)], q, r.get());
  if (!r->reader) throw InputError(std::string("DDS: cannot subscribe to ") + topicName(topic));
}

void DdsTransport::unsubscribe(Topic topic) {
  if (impl_->stopping) return;  // the teardown deletes every reader
  impl_->dropReader(topic);
}

void DdsTransport::Impl::dropReader(Topic topic) {
  std::unique_ptr<Reader> r;
  {
    std::lock_guard lock(entities);
    r = std::move(readers[static_cast<size_t>(topic)]);
  }
  // Deleting the reader waits for a listener call in progress to return.
  if (r && r->reader) subscriber->delete_datareader(r->reader);
}

bool DdsTransport::peerReads(Topic topic, uint16_t node) {
  Impl& d = *impl_;
  GuidPrefix_t prefix;
  {
    std::lock_guard lock(d.mutex);
    auto it = d.peers.find(node);
    if (it == d.peers.end()) return false;
    prefix = it->second.first;
  }
  if (d.stopping) return false;
  {
    std::lock_guard lock(d.entities);
    if (d.closed) return false;
  }
  std::lock_guard lock(d.match_mutex);
  return d.matched[static_cast<size_t>(topic)].count(prefix) > 0;
}

namespace {
std::atomic<int> g_teardowns_running{0};
}

int DdsTransport::teardownsRunning() { return g_teardowns_running.load(); }

void DdsTransport::stop() {
  Impl& d = *impl_;
  PeerInfo last;
  {
    std::lock_guard lock(d.mutex);
    if (!d.running) return;
    d.self.leaving = true;
    last = d.self;
    d.running = false;
  }
  d.stopping = true;
  d.wake.notify_all();
  if (d.heartbeat.joinable()) d.heartbeat.join();
  // The teardown runs inside Fast DDS, under its locks, and Fast DDS 2.9 has lock-order
  // deadlocks there (eProsima/Fast-DDS#3468: a reader that leaves while the asynchronous sender
  // writes; #6463: a tear-down while a peer still delivers). One must not keep a node from ending its run: its map,
  // trajectory and report come after stop(). So the teardown gets its own thread and the time
  // its flush may take, plus a margin; past that it is left behind (it holds the state it
  // uses) and the program ends without running Fast DDS's exit handlers (apps/main.cpp).
  ++g_teardowns_running;
  auto finished = std::make_shared<std::promise<void>>();
  auto done = finished->get_future();
  std::thread teardown([impl = impl_, last, finished] {
    const ScopedThreadName name("dds-teardown");
    impl->teardown(last);
    --g_teardowns_running;
    finished->set_value();
  });
  const auto limit = std::chrono::milliseconds(d.options.leave_flush_ms + d.options.teardown_margin_ms);
  if (done.wait_for(limit) == std::future_status::ready) {
    teardown.join();
    return;
  }
  teardown.detach();
  spdlog::error("node {}: DDS did not shut down within {:.1f} s (a deadlock inside Fast DDS); leaving it behind",
                d.self_node.load(), std::chrono::duration<double>(limit).count());
}

void DdsTransport::Impl::teardown(const PeerInfo& last) {
  if (options.teardown_hook) options.teardown_hook();
  {
    std::lock_guard lock(entities);
    closed = true;
    // What is queued goes out before the leaving notice: a peer that hears of the leaving
    // drops its subscriptions to this node's topics, and with them the last packets (the
    // end-of-run Done was lost that way in 4 of 20 bench runs).
    const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(options.leave_flush_ms);
    for (auto* w : writers) {
      const double left = std::chrono::duration<double>(until - std::chrono::steady_clock::now()).count();
      if (w && left > 0) w->wait_for_acknowledgments(Duration_t(left));
    }
  }
  write(last);  // peers learn at once, not after the lease
  if (node_writer) node_writer->wait_for_acknowledgments(Duration_t(0, 200'000'000));
  for (int i = 0; i < kTopicCount; ++i) dropReader(static_cast<Topic>(i));
  participant->delete_contained_entities();
  peer_events.close();
  if (peer_thread.joinable()) peer_thread.join();
  dds::DomainParticipantFactory::get_instance()->delete_participant(participant);
  participant = nullptr;
}

TrafficReport DdsTransport::traffic() const { return impl_->counter.report(); }

}  // namespace hiveslam::communication
