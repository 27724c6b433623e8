#include "communication/message.hpp"

namespace hiveslam::communication {

const char* taskName(Task t) {
  switch (t) {
    case Task::Tracking: return "tr";
    case Task::Mapping: return "lm";
    case Task::LoopClosing: return "lc";
  }
  return "?";
}

bool parseTask(const std::string& name, Task& out) {
  for (Task t : {Task::Tracking, Task::Mapping, Task::LoopClosing})
    if (name == taskName(t)) {
      out = t;
      return true;
    }
  return false;
}

const char* topicName(Topic t) {
  switch (t) {
    case Topic::TrKeyframes: return "rt/hiveslam/tr/keyframes";
    case Topic::LmKeyframes: return "rt/hiveslam/lm/keyframes";
    case Topic::LmMap: return "rt/hiveslam/lm/map";
    case Topic::LcMap: return "rt/hiveslam/lc/map";
    case Topic::Count: break;
  }
  return "?";
}

}  // namespace hiveslam::communication
