// Prints cal::fixed_text(VALUE, DECIMALS) for each pair of arguments, one a line: the terminal's
// and the reports' way of writing a number, for present_numbers_test.py to hold the pages'
// writer (daq/web/present.js) against. A value is read as strtod reads it (the nearest double,
// as JavaScript's Number() reads the same text).
#include <cstdio>
#include <cstdlib>
#include <string>

#include "cal/analysis/fixed_text.hpp"

int main(int argc, char** argv) {
  if (argc % 2 != 1) {
    std::fprintf(stderr, "usage: fixed_text_print VALUE DECIMALS [VALUE DECIMALS ...]\n");
    return 2;
  }
  for (int i = 1; i + 1 < argc; i += 2) {
    char* end = nullptr;
    const double v = std::strtod(argv[i], &end);
    if (end == argv[i] || *end != '\0') {
      std::fprintf(stderr, "not a number: %s\n", argv[i]);
      return 2;
    }
    std::printf("%s\n", cal::fixed_text(v, std::atoi(argv[i + 1])).c_str());
  }
  return 0;
}
