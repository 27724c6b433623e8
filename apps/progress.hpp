#pragma once
// A one-line progress display: rewritten in place on a terminal, every 10% otherwise.
#include <unistd.h>

#include <cstdio>
#include <string>

namespace hiveslam::apps {

class Progress {
 public:
  explicit Progress(std::string label) : label_(std::move(label)), tty_(isatty(fileno(stderr))) {}
  // `total` 0: not known up front (a live topic); then every 100.
  void update(int done, int total) {
    if (total <= 0) {
      if (tty_) std::fprintf(stderr, "\r%s %d", label_.c_str(), done);
      else if (done % 100 == 0) std::fprintf(stderr, "%s %d\n", label_.c_str(), done);
      return;
    }
    const int percent = total > 0 ? 100 * done / total : 0;
    if (tty_) {
      std::fprintf(stderr, "\r%s %d/%d (%d%%)", label_.c_str(), done, total, percent);
      if (done == total) std::fprintf(stderr, "\n");
    } else if (percent / 10 != last_ / 10 || done == total) {
      std::fprintf(stderr, "%s %d/%d (%d%%)\n", label_.c_str(), done, total, percent);
    }
    last_ = percent;
  }

 private:
  std::string label_;
  bool tty_;
  int last_ = -1;
};

}  // namespace hiveslam::apps
