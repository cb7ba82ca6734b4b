#pragma once
// A file a command writes whole (a report, a table, a HAL file): one place that says when it
// could not be, so that no command prints "written" over a truncated file.
#include <filesystem>
#include <string>
#include <string_view>

namespace daq {

// Writes `bytes` to `path` (created, or truncated); throws InputError "PATH: cannot write the
// WHAT" when any of it was not written or the file did not close cleanly (a full disk shows
// only then).
void write_output_file(const std::filesystem::path& path, std::string_view bytes,
                       std::string_view what);

// A report page (HTML) to `path`, then "report written to PATH" on stderr.
void write_report_page(const std::string& path, std::string_view html);

}  // namespace daq
