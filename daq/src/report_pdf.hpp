#pragma once
// Printing an HTML report to PDF with headless Chromium (`daq report --format pdf`, and the
// operator's page's PDF links).
#include <filesystem>

namespace daq {

// Prints html_file to pdf ($CALDAQ_CHROMIUM, else chromium on the PATH); the PDF is checked
// ("%PDF"), not assumed. Throws cal::InputError naming the file, the browser and its log.
void print_pdf(const std::filesystem::path& html_file, const std::filesystem::path& pdf);

}  // namespace daq
