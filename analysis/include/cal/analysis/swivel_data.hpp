#pragma once
// The fitted axis average lines of a swivel table (kinematics type P) written as a SINUMERIK
// CYCLE800 swivel data record: the orientable toolholder's system variables $TC_CARR1..65 of
// one record n, as `$TC_CARRk[n]=value` assignments of a part program. Numbering (SINUMERIK
// 828D/840D sl Function Manual W1, "Toolholder with orientation capability"): I1 = $TC_CARR1..3,
// I2 = 4..6, V1 = 7..9, V2 = 10..12, I3 = 15..17, I4 = 18..20, axis names 21, 22, kinematic
// type 23, fine offsets of I1..I4 = the basic number + 40. Meaning (Commissioning Manual,
// "Swivel table"): I2 from the machine reference point to the pivot point of the 1st rotary axis,
// I3 from there to the pivot point of the 2nd, I4 = -(I2 + I3); the 1st axis carries the 2nd
// ("Rotary axis 2 is based on rotary axis 1"); the angle "counted positively for clockwise
// rotation facing the direction of the rotation vector". Quoted, with what the text leaves
// open and what we chose, in docs/kinematics.md, "SINUMERIK CYCLE800 swivel data". Pure: no I/O.
#include <string>
#include <string_view>
#include <vector>

#include "cal/analysis/rotary.hpp"

namespace cal::kinematics {

struct SwivelRecord {
  int number = 1;            // n of $TC_CARRk[n]: the swivel data record (toolholder) number
  char kind = 'P';           // $TC_CARR23: "P", only the part can rotate (a swivel table)
  std::string axis1, axis2;  // $TC_CARR21, 22: the channel's names of the 1st and 2nd axes
  Vec3 i1_mm{}, i2_mm{}, i3_mm{}, i4_mm{};  // offset vectors, machine axes X Y Z, mm
  Vec3 v1{}, v2{};                          // rotary axis vectors (unit length written)
};

struct SwivelOptions {
  int number = 1;
  // The control's positive angle turns the table the other way than the model's angle (the
  // table's own right-handed rotation about +X, +Y, +Z): V1 and V2 are negated. Siemens'
  // CYCLE800 checklist: "If the linear axis or the rotary axis moves the workpiece, the
  // direction of motion of the axis and also the sign of the rotary axis vector change."
  bool reverse_angles = false;
};

// The record of a model whose rotary axes are table axes only: one (its 1st axis), or two in
// the model's chain order [carried, carrier] (a C table on an A or B cradle: {C, A} -> 1st
// axis A, 2nd C). Each pivot point is the axis's actual line's point at its nominal pivot's
// plane (pivot + position error), each V its actual direction R(orientation) d. Throws
// InputError for any other machine, and for a non-finite pivot or location error (nothing
// non-finite goes into a controller table).
SwivelRecord sinumerik_swivel_record(const FiveAxisMachine& machine,
                                     const SwivelOptions& options = {});

// The part program: a comment block (source, meaning of each vector, what is not written), the
// assignments of $TC_CARR1..23 and the fine offsets $TC_CARR41..46, 55..60 (0: this record is
// the whole description), then M30. mm to 6 decimals, V to 9. Throws InputError for a
// non-finite value.
std::string sinumerik_swivel_program(const SwivelRecord& record, std::string_view origin_comment);

// Such a program read back (what a simulated control applies): `$TC_CARRk[n]=value` lines of one
// record for k in 1..23, 41..46, 55..60, ';' comments, blank lines, M30 / M17 / M2. Throws
// InputError naming `where` and the line for anything else (another variable or record, a value
// that is not a finite number, a variable given twice, a non-zero fine offset, a kinematic type
// other than P).
SwivelRecord parse_sinumerik_swivel_program(std::string_view text, std::string_view where);

// The control's machine with this record: the model's chain and linear part, its table axes'
// nominal pivots on the record's lines (1st axis through I2, 2nd through I2 + I3) and along V1,
// V2 (a V opposite to the axis's direction is read as written with reverse_angles: the same line,
// the angle's sign changed), no location or component errors otherwise. Throws InputError as
// sinumerik_swivel_record, for a zero V or one more than 0.01 rad off the axis's nominal
// direction, or axis names other than the model's letters.
FiveAxisMachine swivel_control_machine(const SwivelRecord& record, const FiveAxisMachine& model);

// Why no HEIDENHAIN kinematics is written: the public text that was found and what it does not
// state (docs/kinematics.md, "HEIDENHAIN"). For the command's refusal.
std::string_view heidenhain_not_written_reason();

}  // namespace cal::kinematics
