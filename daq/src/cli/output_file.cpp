#include "output_file.hpp"

#include <fmt/format.h>

#include <cstdio>
#include <fstream>

#include "cal/analysis/error.hpp"

namespace daq {

void write_output_file(const std::filesystem::path& path, std::string_view bytes,
                       std::string_view what) {
  std::ofstream out(path, std::ios::binary);
  if (!out.write(bytes.data(), static_cast<std::streamsize>(bytes.size())) || !(out.close(), out))
    throw cal::InputError(fmt::format("{}: cannot write the {}", path.string(), what));
}

void write_report_page(const std::string& path, std::string_view html) {
  write_output_file(path, html, "report");
  fmt::print(stderr, "report written to {}\n", path);
}

}  // namespace daq
