#pragma once
// The one exception type for bad input: its message is a single line that names the file
// (or the message, peer, setting) at fault. Commands print it and exit non-zero.
#include <stdexcept>
#include <string>

namespace hiveslam {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace hiveslam
