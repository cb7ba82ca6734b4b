// daq report: self-contained HTML (or PDF, printed by headless Chromium) reports of stored
// runs: one run, a campaign, or a comparison of the same test over time.
#include <fcntl.h>
#include <fmt/format.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <iterator>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <thread>

#include "cal/analysis/error.hpp"
#include "cal/storage/store.hpp"
#include "command.hpp"
#include "commands.hpp"
#include "database.hpp"
#include "output_file.hpp"
#include "progress.hpp"
#include "report/report.hpp"
#include "report_pdf.hpp"
#include "run_version.hpp"

namespace daq {
namespace {

namespace fs = std::filesystem;

struct ReportOptions {
  std::string db;
  std::vector<std::int64_t> runs;
  std::string campaign;
  bool compare = false;
  std::int64_t as_found = 0, as_left = 0;
  std::int64_t verify = 0;                   // the as-left run of a compensation loop
  std::optional<std::int64_t> compensation;  // with --verify: the table (default: daq verify's)
  std::string format = "html";
  std::string output;
  std::string standard;
  bool json = false;
  int version = 0;  // of the one run's stops (central store); 0: the current one
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

// A private directory for one printing (0700, made by mkdtemp), removed with what is in it.
class PrivateDir {
 public:
  PrivateDir() {
    std::string name = (fs::temp_directory_path() / "caldaq-pdf-XXXXXX").string();
    if (::mkdtemp(name.data()) == nullptr)
      throw cal::InputError(fmt::format("{}: cannot make a private directory to print in: {}", name,
                                        std::strerror(errno)));
    path_ = name;
  }
  ~PrivateDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  PrivateDir(const PrivateDir&) = delete;
  PrivateDir& operator=(const PrivateDir&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

// The browser's environment: ours, with its home and XDG directories in the private directory
// (nothing of the service's own profile, cache or settings is read or written).
std::vector<std::string> browser_environment(const fs::path& home) {
  std::vector<std::string> env;
  for (char** e = environ; *e != nullptr; ++e) {
    const std::string_view v(*e);
    if (!v.starts_with("HOME=") && !v.starts_with("XDG_")) env.emplace_back(v);
  }
  env.push_back("HOME=" + home.string());
  for (const char* xdg : {"XDG_CONFIG_HOME", "XDG_CACHE_HOME", "XDG_DATA_HOME"})
    env.push_back(fmt::format("{}={}", xdg, home.string()));
  return env;
}

struct Exit {
  int status = 0;
  bool timed_out = false;
};

// Runs argv[0] (no shell: a path with a quote is just a path) with stdin from /dev/null and its
// output into `log`, in a process group of its own, and waits up to `limit`; a browser still
// running then is killed with its helpers.
Exit run_browser(const std::vector<std::string>& args, const fs::path& log, const fs::path& home,
                 std::chrono::seconds limit, const std::function<void()>& waiting) {
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  auto env_text = browser_environment(home);
  std::vector<char*> envp;
  for (auto& e : env_text) envp.push_back(e.data());
  envp.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP);
  posix_spawnattr_setpgroup(&attr, 0);
  pid_t pid = 0;
  const bool bare = args.front().find('/') == std::string::npos;  // a name: searched on PATH
  const int rc = bare ? ::posix_spawnp(&pid, argv[0], &actions, &attr, argv.data(), envp.data())
                      : ::posix_spawn(&pid, argv[0], &actions, &attr, argv.data(), envp.data());
  posix_spawnattr_destroy(&attr);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0)
    throw cal::InputError(
        fmt::format("cannot start the browser {}: {}", args.front(), std::strerror(rc)));
  Exit e;
  const auto deadline = std::chrono::steady_clock::now() + limit;
  while (::waitpid(pid, &e.status, WNOHANG) == 0) {
    if (std::chrono::steady_clock::now() > deadline) {
      e.timed_out = true;
      ::kill(-pid, SIGKILL);
      ::waitpid(pid, &e.status, 0);
      break;
    }
    if (waiting) waiting();
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ::kill(-pid, SIGKILL);  // helpers the browser left behind, if any
  return e;
}

// Copies the browser's output to where the error message says it is (not following a link put
// there in its place).
void keep_log(const fs::path& from, const fs::path& to) {
  std::ifstream in(from, std::ios::binary);
  const std::string text(std::istreambuf_iterator<char>(in), {});
  const int fd = ::open(to.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_NOFOLLOW | O_CLOEXEC, 0600);
  if (fd < 0) return;
  [[maybe_unused]] const auto written = ::write(fd, text.data(), text.size());
  ::close(fd);
}

}  // namespace

// Prints the report to pdf with headless Chromium, which sees only a private directory holding
// the report (a copy of it, a fresh profile) and has no network: with the report's
// Content-Security-Policy, nothing outside the report can come into the PDF.
std::size_t print_pdf_text(std::string_view html, const fs::path& pdf, const fs::path& log,
                           const std::function<void()>& waiting) {
  const auto browser = find_chromium();
  const PrivateDir dir;
  // The page alone in its directory; the profile, the PDF and the browser's output beside it.
  const auto page = dir.path() / "page" / "report.html";
  if (std::error_code ec; !fs::create_directory(page.parent_path(), ec))
    throw cal::InputError(
        fmt::format("{}: cannot make the directory to print in", page.parent_path().string()));
  const auto printed = dir.path() / "report.pdf";
  const auto output = dir.path() / "chromium.log";
  write_output_file(page, html, "report to print");
  const std::vector<std::string> args{
      browser, "--headless", "--no-sandbox", "--disable-gpu", "--no-pdf-header-footer",
      "--print-to-pdf-no-header", "--user-data-dir=" + (dir.path() / "profile").string(),
      "--no-first-run", "--no-default-browser-check", "--disable-extensions", "--disable-sync",
      "--disable-background-networking", "--disable-component-update",
      // No network: every request goes to a closed local port, loopback included (Chromium
      // otherwise bypasses a proxy for it), and no name resolves.
      "--proxy-server=127.0.0.1:9", "--proxy-bypass-list=<-loopback>",
      "--host-resolver-rules=MAP * ~NOTFOUND", "--print-to-pdf=" + printed.string(),
      "file://" + page.string()};
  const auto e = run_browser(args, output, dir.path(), std::chrono::seconds(180), waiting);
  std::ifstream in(printed, std::ios::binary);
  const std::string bytes(std::istreambuf_iterator<char>(in), {});
  const bool exited = !e.timed_out && WIFEXITED(e.status);
  if (!exited || WEXITSTATUS(e.status) != 0 || !bytes.starts_with("%PDF")) {
    keep_log(output, log);
    throw cal::InputError(
        fmt::format("{}: Chromium ({}) did not print the report ({}); its output is in {}",
                    pdf.string(), browser,
                    e.timed_out ? "it did not finish within 180 s"
                    : exited    ? fmt::format("exit status {}", WEXITSTATUS(e.status))
                                : fmt::format("killed by signal {}", WTERMSIG(e.status)),
                    log.string()));
  }
  write_output_file(pdf, bytes, "PDF");
  return bytes.size();
}

void print_pdf(const fs::path& html_file, const fs::path& pdf) {
  std::ifstream in(html_file, std::ios::binary);
  if (!in) throw cal::InputError(fmt::format("{}: cannot read the report", html_file.string()));
  const std::string html(std::istreambuf_iterator<char>(in), {});
  print_pdf_text(html, pdf, fs::path(pdf).concat(".log"));
}

namespace {

void run_report_command(ReportOptions o) {
  if (o.format != "html" && o.format != "pdf")
    throw cal::InputError(fmt::format("report: --format {}: use html or pdf", o.format));
  const auto reader = open_run_reader(o.db);  // either store (--db postgresql://...)
  const auto& store = *reader;
  if (!o.campaign.empty()) {
    for (const auto& r : store.runs())
      if (r.campaign == o.campaign) o.runs.push_back(r.id);
    if (o.runs.empty())
      throw cal::InputError(
          fmt::format("{}: no runs in campaign \"{}\" (see daq runs)", store.name(), o.campaign));
  }
  if (o.runs.empty() && !o.as_found && !o.as_left && !o.verify)
    throw cal::InputError(
        "report: give one or more RUN numbers, --campaign, --as-found and --as-left, or "
        "--verify RUN");
  if (o.verify && (!o.runs.empty() || o.as_found || o.as_left || o.compare))
    throw cal::InputError("report: --verify RUN reports that run alone (no other runs)");
  if (o.compensation && !o.verify)
    throw cal::InputError("report: --compensation is for --verify RUN");
  if (o.version != 0) {
    if (o.runs.size() != 1 || !o.campaign.empty() || o.compare || o.as_found || o.as_left ||
        o.verify)
      throw cal::InputError("report: --version N is for the report of one RUN");
    choose_version(*reader, o.db, o.runs.front(), o.version);
  }
  const fs::path named_output(o.output);
  // How far a long report is, on the terminal (stderr) only, as daq export shows it; not when
  // the report itself goes to a stream (-o /dev/stdout), which may be that terminal.
  std::error_code stream_error;
  const bool show_progress = o.output.empty() || !fs::exists(named_output, stream_error) ||
                             fs::is_regular_file(named_output, stream_error);
  const std::string job = o.verify ? fmt::format("verification report of run {}", o.verify)
                          : o.as_found || o.as_left
                              ? fmt::format("report of runs {} and {}", o.as_found, o.as_left)
                              : fmt::format("report of run{} {}", o.runs.size() > 1 ? "s" : "",
                                            fmt::join(o.runs, ", "));
  // Made at the first batch: a report that reads no long stream (a linear or circle run's
  // targets) shows no count.
  std::optional<TerminalProgress> reading;
  std::uint64_t shown = 0;
  cal::daq::report::Options ro{.standard = o.standard, .software = "daq 0.1.0"};
  ro.version = o.version;
  ro.reading_progress = [&](std::uint64_t done, std::uint64_t total) {
    if (done < shown) reading.reset(), shown = 0;  // the next run of a campaign: its own count
    if (!reading) reading.emplace(job, "readings", total, show_progress);
    reading->add(done - shown);
    reading->tick();
    shown = done;
  };
  std::string html, kind, stem;
  if (o.verify) {
    html = cal::daq::report::verification_report(store, o.verify, o.compensation, ro);
    kind = "verification";
    stem = fmt::format("verification-run-{}", o.verify);
    o.runs = {o.verify};
  } else if (o.as_found || o.as_left) {
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
  reading.reset();  // clears its line
  const fs::path out = o.output.empty() ? fs::path(stem + "." + o.format) : named_output;
  std::uintmax_t streamed_bytes = html.size();  // what went to a stream, which has no size
  if (o.format == "html") {
    write_output_file(out, html, "report");
  } else {
    // Chromium's output, if it fails, beside the PDF; a stream (-o /dev/stdout, a pipe) has no
    // "beside", so in the temporary directory.
    std::error_code ec;
    const bool to_stream = fs::exists(out, ec) && !fs::is_regular_file(out, ec);
    const auto log =
        to_stream ? fs::temp_directory_path() / fmt::format("caldaq-report-{}.pdf.log", ::getpid())
                  : fs::path(out).concat(".log");
    // Chromium counts nothing it tells: the time it has taken so far.
    TerminalProgress printing(job + ": printing the PDF with Chromium", "", 0, show_progress);
    streamed_bytes = print_pdf_text(html, out, log, [&printing] { printing.tick(); });
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
  const auto [cmd, o] = add_command<ReportOptions>(
      app, "report", run_report_command,
      "Write a self-contained report (HTML, or PDF through headless Chromium) of one stored run, "
      "of several runs or a campaign, or a comparison of the same test over time");
  cmd->add_option("RUN", o->runs, "Stored run numbers (see daq runs)");
  add_read_db_option(*cmd, o->db);
  add_version_option(*cmd, o->version);
  cmd->add_option("--campaign", o->campaign, "Report every run of this campaign");
  cmd->add_flag("--compare", o->compare,
                "Overlay the same test of several runs and show the results over time");
  cmd->add_option(
      "--as-found", o->as_found,
      "With --as-left: the run before the compensation, side by side with the run after");
  cmd->add_option("--as-left", o->as_left, "With --as-found: the run after the compensation");
  cmd->add_option("--verify", o->verify,
                  "The compensation loop's report of this as-left run (what daq verify checks): "
                  "the table, the as-found and as-left runs, what the table was to remove and "
                  "what it did, the finding and the verdict");
  cmd->add_option("--compensation", o->compensation,
                  "With --verify: the stored compensation (default: daq verify's, the newest "
                  "of the run's machine and axis stored before it)");
  cmd->add_option("-f,--format", o->format, "html or pdf")->capture_default_str();
  cmd->add_option("-o,--output", o->output,
                  "Output file (default report-run-N.html, report-runs-..., comparison-runs-..., "
                  "verification-run-N...)");
  cmd->add_option("-s,--standard", o->standard,
                  "Linear runs: evaluate by this standard (default: the run's)");
  cmd->add_flag("--json", o->json, "Print what was written as JSON (caldaq.report.v1)");
}

}  // namespace daq
