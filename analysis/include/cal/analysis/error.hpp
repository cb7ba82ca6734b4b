#pragma once
// The one error type of the analysis library: bad input, with a message that names the input,
// its value and what was expected.
#include <stdexcept>
#include <string>

namespace cal {

class InputError : public std::invalid_argument {
 public:
  explicit InputError(const std::string& what) : std::invalid_argument(what) {}
};

}  // namespace cal
