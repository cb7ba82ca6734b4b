// The caldaq.model.v1 reader on arbitrary text: a model whose values are all within their
// limits (its volumetric error finite at the corners of its travel), written back and read
// again to the same text; or cal::InputError naming the file. Never a crash (a source or
// provenance nested 100 000 deep once overflowed the stack of every dump), a hang or another
// exception.
#include <cmath>
#include <string_view>

#include "cal/analysis/error.hpp"
#include "cal/analysis/kinematics.hpp"
#include "model/model_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace md = cal::daq::model;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const md::Model m = md::parse(text, "fuzz.json");
    const std::string written = md::to_json(m);
    if (md::to_json(md::parse(written, "written.json")) != written) __builtin_trap();
    if (m.travel_mm) {
      const auto& t = *m.travel_mm;
      for (int corner = 0; corner < 8; ++corner) {
        const cal::kinematics::Vec3 p{t[0][corner & 1], t[1][(corner >> 1) & 1],
                                      t[2][(corner >> 2) & 1]};
        const auto e =
            cal::kinematics::volumetric_error(m.machine, p, cal::kinematics::Method::htm);
        for (double v : e.translation_um)
          if (!std::isfinite(v)) __builtin_trap();
      }
    }
  } catch (const cal::InputError&) {
  }
  return 0;
}
