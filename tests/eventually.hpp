#pragma once
// Waits until a condition holds, for what the code under test does on its own threads (a
// departure handled on a node's map handler thread, a batch sent by a map handler).
#include <chrono>
#include <thread>

namespace hiveslam::testing {

template <class Pred>
bool eventually(Pred pred, std::chrono::milliseconds within = std::chrono::seconds(30)) {
  const auto until = std::chrono::steady_clock::now() + within;
  while (!pred()) {
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return true;
}

}  // namespace hiveslam::testing
