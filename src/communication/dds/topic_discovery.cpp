#include "communication/dds/topic_discovery.hpp"

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>

#include <map>
#include <mutex>
#include <set>

#include "common/error.hpp"
#include "common/thread_name.hpp"
#include "communication/dds/participant_security.hpp"

namespace hiveslam::communication {

namespace dds = eprosima::fastdds::dds;
namespace rtps = eprosima::fastrtps::rtps;

struct TopicDiscovery::Impl : public dds::DomainParticipantListener {
  dds::DomainParticipant* participant = nullptr;
  mutable std::mutex mutex;
  struct Entry {
    std::set<rtps::GUID_t> writers, readers;
  };
  // By name and type: two types on one name are two topics that never match.
  std::map<std::pair<std::string, std::string>, Entry> topics;

  // Adds or removes one endpoint of a topic.
  void update(const std::string& topic, const std::string& type, const rtps::GUID_t& guid, bool writer, bool present) {
    std::lock_guard lock(mutex);
    Entry& e = topics[{topic, type}];
    auto& set = writer ? e.writers : e.readers;
    if (present)
      set.insert(guid);
    else
      set.erase(guid);
  }
  void on_publisher_discovery(dds::DomainParticipant*, rtps::WriterDiscoveryInfo&& info) override {
    using S = rtps::WriterDiscoveryInfo;
    if (info.status == S::DISCOVERED_WRITER || info.status == S::REMOVED_WRITER)
      update(info.info.topicName().to_string(), info.info.typeName().to_string(), info.info.guid(), true,
             info.status == S::DISCOVERED_WRITER);
  }
  void on_subscriber_discovery(dds::DomainParticipant*, rtps::ReaderDiscoveryInfo&& info) override {
    using S = rtps::ReaderDiscoveryInfo;
    if (info.status == S::DISCOVERED_READER || info.status == S::REMOVED_READER)
      update(info.info.topicName().to_string(), info.info.typeName().to_string(), info.info.guid(), false,
             info.status == S::DISCOVERED_READER);
  }
};

TopicDiscovery::TopicDiscovery(int domain) : impl_(std::make_unique<Impl>()) {
  if (domain < 0 || domain > 232) throw InputError("DDS domain must be 0-232");
  const ScopedThreadName thread_name("fastdds");
  dds::DomainParticipantQos pq = dds::PARTICIPANT_QOS_DEFAULT;
  pq.name("hiveslam-topics");
  pq.transport().use_builtin_transports = false;
  pq.transport().user_transports.push_back(std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>());
  auto& discovery = pq.wire_protocol().builtin.discovery_config;
  discovery.initial_announcements.count = 5;
  discovery.initial_announcements.period = eprosima::fastrtps::Duration_t(0, 100'000'000);
  dds::StatusMask mask = dds::StatusMask::none();
  applySecurity(pq);
  impl_->participant = dds::DomainParticipantFactory::get_instance()->create_participant(
      static_cast<dds::DomainId_t>(domain), pq, impl_.get(), mask);
  if (!impl_->participant) throw InputError("DDS: cannot create a participant on domain " + std::to_string(domain));
}

TopicDiscovery::~TopicDiscovery() {
  if (impl_->participant) dds::DomainParticipantFactory::get_instance()->delete_participant(impl_->participant);
}

std::vector<DiscoveredTopic> TopicDiscovery::topics() const {
  std::lock_guard lock(impl_->mutex);
  std::vector<DiscoveredTopic> out;
  for (const auto& [key, e] : impl_->topics)
    out.push_back({key.first, key.second, static_cast<int>(e.writers.size()), static_cast<int>(e.readers.size())});
  return out;
}

std::string rosTopicName(const std::string& dds_name) {
  return dds_name.rfind("rt/", 0) == 0 ? dds_name.substr(2) : std::string();
}

std::string rosTypeName(const std::string& dds_type) {
  const std::string marker = "::dds_::";
  const auto at = dds_type.find(marker);
  if (at == std::string::npos || dds_type.empty() || dds_type.back() != '_') return dds_type;
  // Copied with each "::" as '/': replacing in place drew a false -Wrestrict from GCC 12's
  // inlined string code in the Release build.
  std::string pkg;
  for (size_t i = 0; i < at; ++i) {
    if (dds_type.compare(i, 2, "::") == 0) {
      pkg += '/';
      ++i;
    } else {
      pkg += dds_type[i];
    }
  }
  pkg += '/';
  pkg.append(dds_type, at + marker.size(), dds_type.size() - at - marker.size() - 1);
  return pkg;
}

}  // namespace hiveslam::communication
