// A TEMPer HID input report written by hand: the bytes given, zero-padded to the 8 bytes every
// report has (temper/codec.hpp). For the codec's tests and the instrument's replay tests.
#pragma once

#include <initializer_list>
#include <string>

namespace cal::test {

inline std::string temper_report(std::initializer_list<int> bytes) {
  std::string s;
  for (int b : bytes) s.push_back(static_cast<char>(b));
  s.resize(8, '\0');
  return s;
}

}  // namespace cal::test
