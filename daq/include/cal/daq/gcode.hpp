#pragma once
// Part programs for the tests, in the dialects of the common controls (docs/acquisition.md):
// - Fanuc / ISO 6983: G90 G01 X.. F.., dwell G04 P<ms> (Fanuc counts P in ms), arcs G02/G03
//   with I J (G17), M30.
// - Heidenhain conversational: BEGIN PGM .. MM, L X+.. F.., dwell CYCL DEF 9.0/9.1 DWELL, arcs
//   by CC X.. Y.. (centre) and C X.. Y.. DR+/DR-, END PGM.
// - Siemens SINUMERIK: G90 G1 X.. F.., dwell G4 F<s>, arcs G2/G3 with I= J= (incremental
//   centre, the SINUMERIK default), M30.
// The ISO 230-2 program visits every move of the plan (measure, over-run, reposition) with a
// dwell at each measure move; the circle program feeds in, dwells, runs the ccw arc with its
// overshoots, dwells, runs the cw arc back, and feeds out, matching BallbarSegmenter.
#include <string>
#include <string_view>

#include "cal/analysis/iso230_2_targets.hpp"
#include "cal/daq/ballbar.hpp"

namespace cal::daq {

enum class Dialect { fanuc, heidenhain, siemens };
Dialect dialect_from_string(std::string_view s);  // fanuc | iso | heidenhain | siemens

struct LinearProgram {
  char axis = 'X';
  double feed_mm_per_min = 2000.0;
  double dwell_s = 4.0;
  std::string name = "ISO2302";
};

std::string linear_program(const iso230_2::Plan& plan, const LinearProgram& p, Dialect d);

struct CircleProgramSetup {
  double centre_x_mm = 0.0, centre_y_mm = 0.0;  // the table ball, in the XY plane
  std::string name = "BALLBAR";
};

// Arcs are split into segments of at most 180 degrees (a full circle in one block is not
// portable between controls).
std::string circle_program(const BallbarProgram& b, const CircleProgramSetup& s, Dialect d);

}  // namespace cal::daq
