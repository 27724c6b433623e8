#pragma once
// Names the calling thread (as `top -H`, gdb and the per-thread CPU figures of the reports
// show it). Linux keeps 15 characters; longer names are cut.
#include <pthread.h>

#include <string>

namespace hiveslam {

inline void nameThisThread(const std::string& name) {
  pthread_setname_np(pthread_self(), name.substr(0, 15).c_str());
}

// Renames the calling thread for a scope, then restores its name. Threads inherit the name of
// the thread that starts them, so wrapping calls into a library that starts threads (Fast
// DDS: receive, event and flow-control threads) gives those threads a name of their own.
class ScopedThreadName {
 public:
  explicit ScopedThreadName(const std::string& name) {
    pthread_getname_np(pthread_self(), old_, sizeof old_);
    nameThisThread(name);
  }
  ~ScopedThreadName() { pthread_setname_np(pthread_self(), old_); }
  ScopedThreadName(const ScopedThreadName&) = delete;
  ScopedThreadName& operator=(const ScopedThreadName&) = delete;

 private:
  char old_[16] = {};
};

}  // namespace hiveslam
