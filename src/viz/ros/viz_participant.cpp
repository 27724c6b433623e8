#include "viz/ros/viz_participant.hpp"

#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>

#include <vector>

#include "common/error.hpp"
#include "common/thread_name.hpp"
#include "communication/dds/participant_security.hpp"

namespace hiveslam::viz::ros {

namespace dds = eprosima::fastdds::dds;

namespace {

struct Listener : public dds::DataReaderListener {
  std::function<void(dds::DataReader*)> on_data;
  void on_data_available(dds::DataReader* r) override { on_data(r); }
};

}  // namespace

struct VizParticipant::Impl {
  dds::DomainParticipant* participant = nullptr;
  dds::Publisher* publisher = nullptr;
  dds::Subscriber* subscriber = nullptr;
  std::map<std::string, dds::Topic*> topics;
  std::vector<std::unique_ptr<Listener>> listeners;
  std::mutex mutex;

  dds::Topic* topic(const std::string& name, dds::TypeSupport& type) {
    if (auto it = topics.find(name); it != topics.end()) return it->second;
    if (!participant->find_type(type.get_type_name())) type.register_type(participant);
    dds::Topic* t = participant->create_topic(name, type.get_type_name(), dds::TOPIC_QOS_DEFAULT);
    if (!t) throw InputError("DDS: cannot create topic " + name);
    return topics[name] = t;
  }
};

VizParticipant::VizParticipant(int domain, const std::string& name) : impl_(std::make_unique<Impl>()) {
  if (domain < 0 || domain > 232) throw InputError("DDS domain must be 0-232");
  const ScopedThreadName thread_name("fastdds");
  dds::DomainParticipantQos pq = dds::PARTICIPANT_QOS_DEFAULT;
  pq.name(name);
  pq.transport().use_builtin_transports = false;
  pq.transport().user_transports.push_back(std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>());
  auto& discovery = pq.wire_protocol().builtin.discovery_config;
  discovery.initial_announcements.count = 5;
  discovery.initial_announcements.period = eprosima::fastrtps::Duration_t(0, 100'000'000);
  communication::applySecurity(pq);
  impl_->participant = dds::DomainParticipantFactory::get_instance()->create_participant(
      static_cast<dds::DomainId_t>(domain), pq);
  if (!impl_->participant) throw InputError("DDS: cannot create a participant on domain " + std::to_string(domain));
  impl_->publisher = impl_->participant->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
  impl_->subscriber = impl_->participant->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
  if (!impl_->publisher || !impl_->subscriber) {
    close();
    throw InputError("DDS: cannot create a publisher and a subscriber");
  }
}

VizParticipant::~VizParticipant() { close(); }

void VizParticipant::close() {
  if (!impl_->participant) return;
  impl_->participant->delete_contained_entities();
  dds::DomainParticipantFactory::get_instance()->delete_participant(impl_->participant);
  impl_->participant = nullptr;
}

dds::DataWriter* VizParticipant::writer(const std::string& topic, dds::TypeSupport type, int depth) {
  const ScopedThreadName thread_name("fastdds");
  std::lock_guard lock(impl_->mutex);
  dds::DataWriterQos q = dds::DATAWRITER_QOS_DEFAULT;
  q.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
  q.reliability().max_blocking_time = eprosima::fastrtps::Duration_t(0, 20'000'000);
  q.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  q.history().depth = depth;
  // A point cloud spans many datagrams: sent from DDS's own thread, never blocking the caller.
  q.publish_mode().kind = dds::ASYNCHRONOUS_PUBLISH_MODE;
  dds::DataWriter* w = impl_->publisher->create_datawriter(impl_->topic(topic, type), q);
  if (!w) throw InputError("DDS: cannot create a writer of " + topic);
  return w;
}

dds::DataReader* VizParticipant::reader(const std::string& topic, dds::TypeSupport type, int depth,
                                        std::function<void(dds::DataReader*)> on_data, bool reliable) {
  const ScopedThreadName thread_name("fastdds");
  std::lock_guard lock(impl_->mutex);
  dds::DataReaderQos q = dds::DATAREADER_QOS_DEFAULT;
  q.reliability().kind = reliable ? dds::RELIABLE_RELIABILITY_QOS : dds::BEST_EFFORT_RELIABILITY_QOS;
  q.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  q.history().depth = depth;
  auto listener = std::make_unique<Listener>();
  listener->on_data = std::move(on_data);
  dds::DataReader* r = impl_->subscriber->create_datareader(impl_->topic(topic, type), q, listener.get());
  if (!r) throw InputError("DDS: cannot create a reader of " + topic);
  impl_->listeners.push_back(std::move(listener));
  return r;
}

bool hasReaders(dds::DataWriter* writer) {
  dds::PublicationMatchedStatus status;
  return writer->get_publication_matched_status(status) == ReturnCode_t::RETCODE_OK && status.current_count > 0;
}

}  // namespace hiveslam::viz::ros
