#pragma once
// A DDS participant of its own for the live view's ROS topics, beside the node's transport (whose
// traffic counters and QoS stay as they were), with typed writers and readers on it. UDP only,
// as the node's: a restarted node must not inherit a dead one's shared-memory port
// (dds_transport.cpp).
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>

namespace hiveslam::viz::ros {

class VizParticipant {
 public:
  explicit VizParticipant(int domain, const std::string& name);
  ~VizParticipant();
  VizParticipant(const VizParticipant&) = delete;
  VizParticipant& operator=(const VizParticipant&) = delete;

  // A writer of `topic` (a DDS name, "rt/..."): reliable, the newest `depth` samples kept.
  eprosima::fastdds::dds::DataWriter* writer(const std::string& topic, eprosima::fastdds::dds::TypeSupport type, int depth);
  // A reader keeping `depth`; `on_data` runs on a DDS thread when samples arrive. Best effort
  // (the default) matches reliable and best-effort writers alike; a reliable one also gets a
  // writer's last messages before it leaves (the end of a run).
  eprosima::fastdds::dds::DataReader* reader(const std::string& topic, eprosima::fastdds::dds::TypeSupport type, int depth,
                                             std::function<void(eprosima::fastdds::dds::DataReader*)> on_data,
                                             bool reliable = false);
  // Deletes everything it made (readers' callbacks end first).
  void close();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Whether any reader listens: a message nobody reads is not built.
bool hasReaders(eprosima::fastdds::dds::DataWriter* writer);

// Takes every valid sample of type T from `reader`, newest last.
template <class T>
void takeAll(eprosima::fastdds::dds::DataReader* reader, const std::function<void(T&)>& f) {
  T sample;
  eprosima::fastdds::dds::SampleInfo info;
  while (reader->take_next_sample(&sample, &info) == ReturnCode_t::RETCODE_OK)
    if (info.valid_data) f(sample);
}

}  // namespace hiveslam::viz::ros
