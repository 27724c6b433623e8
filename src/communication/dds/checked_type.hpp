#pragma once
// A fastddsgen type whose deserialization drops a malformed sample instead of throwing. The
// generated code catches only Fast CDR's NotEnoughMemoryException; a bool byte other than 0 or 1
// (or a bounded sequence past its bound) threw BadParamException out of take_next_sample, on
// Fast DDS's listener thread, and std::terminate ended the node: one announcement from anyone on
// the domain stopped every node on it (fuzz/announcement_fuzzer.cpp found it). Every type a
// hiveslam reader takes goes through this.
#include <fastcdr/exceptions/Exception.h>
#include <fastdds/rtps/common/SerializedPayload.h>

namespace hiveslam::communication {

inline void ignoreDrop() {}

// `OnDrop` is called for each dropped sample. (A default of nullptr tested with `if constexpr`
// does not compile under GCC 12's -fsanitize=address: a function's address is not a constant
// expression there.)
template <class Generated, void (*OnDrop)() = ignoreDrop>
class CheckedType : public Generated {
 public:
  bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data) override {
    try {
      return Generated::deserialize(payload, data);
    } catch (const eprosima::fastcdr::exception::Exception&) {
      OnDrop();
      return false;
    }
  }
};

}  // namespace hiveslam::communication
