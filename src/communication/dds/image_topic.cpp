#include "communication/dds/image_topic.hpp"

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
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
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastdds/rtps/transport/shared_mem/SharedMemTransportDescriptor.h>

#include <algorithm>
#include <cctype>
#include <condition_variable>
#include <deque>
#include <mutex>

#include "common/error.hpp"
#include "common/thread_name.hpp"
#include "communication/dds/checked_type.hpp"
#include "communication/dds/participant_security.hpp"
#include "sensor_msgs/msg/ImagePubSubTypes.h"

namespace hiveslam::communication {

namespace dds = eprosima::fastdds::dds;
using eprosima::fastrtps::Duration_t;

std::string ddsTopicName(const std::string& ros_topic) {
  std::string name = ros_topic;
  if (!name.empty() && name.front() == '/') name.erase(0, 1);
  bool ok = !name.empty() && name.back() != '/' && name.find("//") == std::string::npos;
  for (char c : name)
    ok = ok && (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '/');
  if (!ok) throw InputError("invalid ROS topic name '" + ros_topic + "' (e.g. /camera/image_raw)");
  return "rt/" + name;
}

namespace {

// A participant with one topic of the Image type, deleted with everything in it.
struct ImageParticipant {
  dds::DomainParticipant* participant = nullptr;
  dds::TypeSupport type{new CheckedType<sensor_msgs::msg::ImagePubSubType>()};
  dds::Topic* topic = nullptr;

  ImageParticipant(int domain, const std::string& ros_topic) {
    const std::string name = ddsTopicName(ros_topic);
    if (domain < 0 || domain > 232) throw InputError("DDS domain must be 0-232");
    const ScopedThreadName thread_name("fastdds");
    // Default transports, shared memory included, unlike the nodes' UDP-only participants
    // (dds_transport.cpp): a 360 KB image is six 64 KB datagrams, more than the kernel's
    // default socket buffer (208 KB), and UDP alone delivered 10 of sweep's 800 frames to a
    // 1-node TR and 166 to a 3-node one. The price is the shared-memory port
    // hazard on restart described there, for a TR restarted while the camera keeps publishing.
    dds::DomainParticipantQos pq = dds::PARTICIPANT_QOS_DEFAULT;
    pq.wire_protocol().builtin.discovery_config.initial_announcements.count = 5;
    pq.wire_protocol().builtin.discovery_config.initial_announcements.period = Duration_t(0, 100'000'000);
    if (secure()) {  // the same transports, made here so that applySecurity sizes the UDP one
      pq.transport().use_builtin_transports = false;
      pq.transport().user_transports.push_back(std::make_shared<eprosima::fastdds::rtps::SharedMemTransportDescriptor>());
      pq.transport().user_transports.push_back(std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>());
    }
    applySecurity(pq);
    participant = dds::DomainParticipantFactory::get_instance()->create_participant(
        static_cast<dds::DomainId_t>(domain), pq);
    if (!participant) throw InputError("DDS: cannot create a participant on domain " + std::to_string(domain));
    type.register_type(participant);
    topic = participant->create_topic(name, type.get_type_name(), dds::TOPIC_QOS_DEFAULT);
    if (!topic) {
      close();
      throw InputError("DDS: cannot create topic " + name);
    }
  }
  ~ImageParticipant() { close(); }
  void close() {
    if (!participant) return;
    participant->delete_contained_entities();
    dds::DomainParticipantFactory::get_instance()->delete_participant(participant);
    participant = nullptr;
  }
};

}  // namespace

struct ImageTopicWriter::Impl : public dds::DataWriterListener {
  ImageParticipant p;
  dds::DataWriter* writer = nullptr;
  mutable std::mutex mutex;
  mutable std::condition_variable matched_changed;
  int matched = 0;

  Impl(int domain, const std::string& ros_topic) : p(domain, ros_topic) {
    const ScopedThreadName thread_name("fastdds");
    dds::Publisher* publisher = p.participant->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
    dds::DataWriterQos q = dds::DATAWRITER_QOS_DEFAULT;
    q.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;  // best-effort readers match it too
    q.reliability().max_blocking_time = Duration_t(0, 50'000'000);
    q.history().kind = dds::KEEP_LAST_HISTORY_QOS;
    q.history().depth = 2;
    q.publish_mode().kind = dds::ASYNCHRONOUS_PUBLISH_MODE;  // images span many datagrams
    writer = publisher ? publisher->create_datawriter(p.topic, q, this) : nullptr;
    if (!writer) throw InputError("DDS: cannot create an image writer");
  }
  ~Impl() override { p.close(); }

  void on_publication_matched(dds::DataWriter*, const dds::PublicationMatchedStatus& s) override {
    std::lock_guard lock(mutex);
    matched = s.current_count;
    matched_changed.notify_all();
  }
};

ImageTopicWriter::ImageTopicWriter(int domain, const std::string& ros_topic)
    : impl_(std::make_unique<Impl>(domain, ros_topic)) {}

ImageTopicWriter::~ImageTopicWriter() = default;

int ImageTopicWriter::readers() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->matched;
}

bool ImageTopicWriter::waitForReaders(int count, std::chrono::milliseconds timeout) const {
  std::unique_lock lock(impl_->mutex);
  return impl_->matched_changed.wait_for(lock, timeout, [&] { return impl_->matched >= count; });
}

void ImageTopicWriter::write(const CameraImage& image) {
  sensor_msgs::msg::Image m;
  m.header().stamp().sec(static_cast<int32_t>(image.stamp_ns / 1'000'000'000));
  m.header().stamp().nanosec(static_cast<uint32_t>(image.stamp_ns % 1'000'000'000));
  m.header().frame_id(image.frame_id);
  m.height(image.height);
  m.width(image.width);
  m.encoding(image.encoding);
  m.is_bigendian(0);
  m.step(image.step);
  m.data(image.data);
  impl_->writer->write(&m);
}

struct ImageTopicReader::Impl : public dds::DataReaderListener {
  ImageParticipant p;
  dds::DataReader* reader = nullptr;
  size_t depth;
  mutable std::mutex mutex;
  std::condition_variable arrived;
  std::deque<CameraImage> queue;
  int writers_now = 0, writers_seen = 0;
  uint64_t received = 0, dropped = 0;

  Impl(int domain, const std::string& ros_topic, size_t depth_) : p(domain, ros_topic), depth(std::max<size_t>(1, depth_)) {
    const ScopedThreadName thread_name("fastdds");
    dds::Subscriber* subscriber = p.participant->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
    dds::DataReaderQos q = dds::DATAREADER_QOS_DEFAULT;
    q.reliability().kind = dds::BEST_EFFORT_RELIABILITY_QOS;
    q.history().kind = dds::KEEP_LAST_HISTORY_QOS;
    q.history().depth = static_cast<int32_t>(depth);
    reader = subscriber ? subscriber->create_datareader(p.topic, q, this) : nullptr;
    if (!reader) throw InputError("DDS: cannot create an image reader");
  }
  // The participant goes first: no callback may run on a half-destroyed listener.
  ~Impl() override { p.close(); }

  void on_data_available(dds::DataReader* r) override {
    sensor_msgs::msg::Image m;
    dds::SampleInfo info;
    while (r->take_next_sample(&m, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      CameraImage image;
      image.stamp_ns = static_cast<int64_t>(m.header().stamp().sec()) * 1'000'000'000 + m.header().stamp().nanosec();
      image.frame_id = m.header().frame_id();
      image.width = m.width();
      image.height = m.height();
      image.step = m.step();
      image.encoding = m.encoding();
      image.data = std::move(m.data());
      std::lock_guard lock(mutex);
      queue.push_back(std::move(image));
      ++received;
      while (queue.size() > depth) {
        queue.pop_front();
        ++dropped;
      }
      arrived.notify_all();
    }
  }
  void on_subscription_matched(dds::DataReader*, const dds::SubscriptionMatchedStatus& s) override {
    std::lock_guard lock(mutex);
    writers_now = s.current_count;
    writers_seen = std::max(writers_seen, static_cast<int>(s.total_count));
    arrived.notify_all();
  }
};

ImageTopicReader::ImageTopicReader(int domain, const std::string& ros_topic, size_t depth)
    : impl_(std::make_unique<Impl>(domain, ros_topic, depth)) {}

ImageTopicReader::~ImageTopicReader() = default;

std::optional<CameraImage> ImageTopicReader::next(std::chrono::milliseconds first, std::chrono::milliseconds idle) {
  Impl& d = *impl_;
  std::unique_lock lock(d.mutex);
  // Over when no image is waiting and every writer that came has gone (its last images are
  // taken first), or after the time out.
  d.arrived.wait_for(lock, d.received > 0 ? idle : first,
                     [&] { return !d.queue.empty() || (d.writers_seen > 0 && d.writers_now == 0); });
  if (d.queue.empty()) return std::nullopt;
  CameraImage image = std::move(d.queue.front());
  d.queue.pop_front();
  return image;
}

bool ImageTopicReader::waitForWriter(std::chrono::milliseconds timeout) {
  Impl& d = *impl_;
  std::unique_lock lock(d.mutex);
  return d.arrived.wait_for(lock, timeout, [&] { return d.writers_now > 0; });
}

uint64_t ImageTopicReader::dropped() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->dropped;
}

}  // namespace hiveslam::communication
