#pragma once
// The one exception type of io/: a file or folder that cannot be created, read, written, locked or
// trusted (a damaged checkpoint, a full disk, a folder of another run). Its message is the one line
// the command line prints; Python raises it as OSError. Programming errors (wrong array shapes)
// stay std::invalid_argument.
#include <stdexcept>

namespace capsflow::io {

class IoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace capsflow::io
