#pragma once
// Printing an HTML report to PDF with headless Chromium (`daq report --format pdf`, and the
// operator's page's PDF links).
#include <cstddef>
#include <filesystem>
#include <functional>
#include <string_view>

namespace daq {

// Prints the report text to pdf (a file or a stream) with headless Chromium ($CALDAQ_CHROMIUM,
// else chromium on the PATH), started without a shell. The browser sees a private directory
// (mkdtemp, 0700, removed afterwards) holding only a copy of the report and a fresh profile,
// has no network (a dead proxy, no name resolution); with the report's
// Content-Security-Policy nothing outside the report (no local file) can get into the PDF.
// The PDF is checked ("%PDF"), not assumed. Returns its size. Throws cal::InputError naming
// the PDF, the browser and `log`, where the browser's output is kept when it fails.
// `waiting`, if given, is called about 50 times a second while the browser prints (progress).
std::size_t print_pdf_text(std::string_view html, const std::filesystem::path& pdf,
                           const std::filesystem::path& log,
                           const std::function<void()>& waiting = {});
// The same for a report in a file; the browser's output goes to PDF.log on failure.
void print_pdf(const std::filesystem::path& html_file, const std::filesystem::path& pdf);

}  // namespace daq
