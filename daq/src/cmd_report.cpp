// daq report: self-contained HTML (or PDF, printed by headless Chromium) reports of stored
// runs: one run, a campaign, or a comparison of the same test over time.
#include <fmt/format.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cal/analysis/error.hpp"
#include "cal/storage/store.hpp"
#include "commands.hpp"
#include "database.hpp"
#include "report/report.hpp"
#include "report_pdf.hpp"

namespace daq {
namespace {

namespace fs = std::filesystem;

struct ReportOptions {
  std::string db;
  std::vector<std::int64_t> runs;
  std::string campaign;
  bool compare = false;
  std::int64_t as_found = 0, as_left = 0;
  std::string format = "html";
  std::string output;
  std::string standard;
  bool json = false;
};

// $CALDAQ_CHROMIUM, else the first of the usual names on the PATH.
std::string find_chromium() {
  if (const char* env = std::getenv("CALDAQ_CHROMIUM"); env && *env) return env;
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "/usr/bin");
  for (std::string dir; std::getline(dirs, dir, ':');)
    for (const char* name : {"chromium", "chromium-browser", "google-chrome"})
      if (::access((fs::path(dir) / name).c_str(), X_OK) == 0)
        return (fs::path(dir) / name).string();
  throw cal::InputError(
      "report --format pdf prints the HTML report with headless Chromium, and none was found "
      "(install Debian's chromium package, or set CALDAQ_CHROMIUM to the browser)");
}

}  // namespace

// Prints html_file to pdf with headless Chromium; the PDF is checked, not assumed.
void print_pdf(const fs::path& html_file, const fs::path& pdf) {
  const auto browser = find_chromium();
  const auto log = fs::path(pdf).concat(".log");
  const std::string cmd = fmt::format(
      "'{}' --headless --no-sandbox --disable-gpu --no-pdf-header-footer "
      "--print-to-pdf-no-header --print-to-pdf='{}' 'file://{}' >'{}' 2>&1",
      browser, pdf.string(), fs::absolute(html_file).string(), log.string());
  std::error_code ec;
  fs::remove(pdf, ec);
  const int status = std::system(cmd.c_str());
  std::ifstream in(pdf, std::ios::binary);
  char magic[5] = {};
  in.read(magic, 4);
  if (status != 0 || std::string_view(magic, 4) != "%PDF")
    throw cal::InputError(
        fmt::format("{}: Chromium ({}) did not print the report (exit status "
                    "{}); its output is in {}",
                    pdf.string(), browser, WEXITSTATUS(status), log.string()));
  fs::remove(log, ec);
}

namespace {

void write_file(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  out.close();
  if (!out) throw cal::InputError(fmt::format("{}: cannot write the report", path.string()));
}

void run_report_command(ReportOptions o) {
  if (o.format != "html" && o.format != "pdf")
    throw cal::InputError(fmt::format("report: --format {}: use html or pdf", o.format));
  const auto store = open_database_read_only(o.db);
  if (!o.campaign.empty()) {
    for (const auto& r : store.runs())
      if (r.campaign == o.campaign) o.runs.push_back(r.id);
    if (o.runs.empty())
      throw cal::InputError(fmt::format("{}: no runs in campaign \"{}\" (see daq runs)",
                                        store.path().string(), o.campaign));
  }
  if (o.runs.empty() && !o.as_found && !o.as_left)
    throw cal::InputError(
        "report: give one or more RUN numbers, --campaign, or --as-found and --as-left");
  const cal::daq::report::Options ro{.standard = o.standard, .software = "daq 0.1.0"};
  std::string html, kind, stem;
  if (o.as_found || o.as_left) {
    if (!o.as_found || !o.as_left)
      throw cal::InputError("report: give both --as-found RUN and --as-left RUN");
    html = cal::daq::report::as_found_as_left_report(store, o.as_found, o.as_left, ro);
    kind = "as-found-as-left";
    stem = fmt::format("as-found-{}-as-left-{}", o.as_found, o.as_left);
    o.runs = {o.as_found, o.as_left};
  } else if (o.compare) {
    html = cal::daq::report::comparison_report(store, o.runs, ro);
    kind = "comparison";
    stem = fmt::format("comparison-runs-{}", fmt::join(o.runs, "-"));
  } else if (o.runs.size() == 1 && o.campaign.empty()) {
    html = cal::daq::report::run_report(store, o.runs.front(), ro);
    kind = "run";
    stem = fmt::format("report-run-{}", o.runs.front());
  } else {
    const std::string title = o.campaign.empty() ? fmt::format("Runs {}", fmt::join(o.runs, ", "))
                                                 : fmt::format("Campaign {}", o.campaign);
    html = cal::daq::report::campaign_report(store, o.runs, title, ro);
    kind = "campaign";
    stem = o.campaign.empty() ? fmt::format("report-runs-{}", fmt::join(o.runs, "-"))
                              : "campaign-report";
  }
  const fs::path out = o.output.empty() ? fs::path(stem + "." + o.format) : fs::path(o.output);
  std::uintmax_t streamed_bytes = html.size();  // what went to a stream, which has no size
  if (o.format == "html") {
    write_file(out, html);
  } else {
    // Chromium prints to a file; a stream (-o /dev/stdout, a pipe) gets the printed file's bytes.
    std::error_code ec;
    const bool to_stream = fs::exists(out, ec) && !fs::is_regular_file(out, ec);
    const auto stem_tmp =
        to_stream ? fs::temp_directory_path() / fmt::format("caldaq-report-{}", ::getpid())
                  : fs::path(out).replace_extension("");
    const auto tmp = fs::path(stem_tmp.string() + ".tmp.html");
    const auto pdf = to_stream ? fs::path(stem_tmp.string() + ".tmp.pdf") : out;
    write_file(tmp, html);
    try {
      print_pdf(tmp, pdf);
      if (to_stream) {
        std::ifstream in(pdf, std::ios::binary);
        write_file(out, std::string(std::istreambuf_iterator<char>(in), {}));
      }
    } catch (...) {
      fs::remove(tmp, ec);
      if (to_stream) fs::remove(pdf, ec);
      throw;
    }
    fs::remove(tmp, ec);
    if (to_stream) {
      streamed_bytes = fs::file_size(pdf, ec);
      fs::remove(pdf, ec);
    }
  }
  // The size written: a pipe or a terminal (-o /dev/stdout) has none to ask the file system for.
  std::error_code size_error;
  const auto file_bytes = fs::file_size(out, size_error);
  const std::uintmax_t bytes = size_error ? streamed_bytes : file_bytes;
  if (o.json) {
    fmt::print("{}\n", nlohmann::json{{"schema", "caldaq.report.v1"},
                                      {"kind", kind},
                                      {"format", o.format},
                                      {"file", out.string()},
                                      {"bytes", bytes},
                                      {"runs", o.runs}}
                           .dump(2));
    return;
  }
  // The status line goes to stderr when the report itself went to a stream (e.g. stdout).
  std::error_code ec;
  std::FILE* status = fs::is_regular_file(out, ec) ? stdout : stderr;
  fmt::print(status, "{} report of run{} {} written to {} ({} bytes)\n", kind,
             o.runs.size() > 1 ? "s" : "", fmt::join(o.runs, ", "), out.string(), bytes);
}

}  // namespace

void add_report_command(CLI::App& app) {
  auto o = std::make_shared<ReportOptions>();
  auto* cmd = app.add_subcommand(
      "report",
      "Write a self-contained report (HTML, or PDF through headless Chromium) of one stored run, "
      "of several runs or a campaign, or a comparison of the same test over time");
  cmd->add_option("RUN", o->runs, "Stored run numbers (see daq runs)");
  add_db_option(*cmd, o->db);
  cmd->add_option("--campaign", o->campaign, "Report every run of this campaign");
  cmd->add_flag("--compare", o->compare,
                "Overlay the same test of several runs and show the results over time");
  cmd->add_option(
      "--as-found", o->as_found,
      "With --as-left: the run before the compensation, side by side with the run after");
  cmd->add_option("--as-left", o->as_left, "With --as-found: the run after the compensation");
  cmd->add_option("-f,--format", o->format, "html or pdf")->capture_default_str();
  cmd->add_option("-o,--output", o->output,
                  "Output file (default report-run-N.html, report-runs-..., comparison-runs-...)");
  cmd->add_option("-s,--standard", o->standard,
                  "Linear runs: evaluate by this standard (default: the run's)");
  cmd->add_flag("--json", o->json, "Print what was written as JSON (caldaq.report.v1)");
  cmd->callback([o] { run_report_command(*o); });
}

}  // namespace daq
