// Serial transport on Boost.Asio's serial_port (termios on Linux). Works with USB-CDC and
// USB-RS-232 adapters and with pseudo-terminals, which the tests and the simulated twins use.
#include <fcntl.h>
#include <fmt/format.h>
#include <sys/file.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <termios.h>

#include <cerrno>
#include <charconv>
#include <cstring>
#include <fstream>
#include <sstream>

#include "asio_session.hpp"
#include "cal/analysis/enum_names.hpp"
#include "cal/analysis/error.hpp"
#include "cal/analysis/text.hpp"

namespace cal::drivers::transport {
namespace {

namespace asio = boost::asio;
using Port = asio::serial_port;

char parity_letter(Parity p) { return p == Parity::none ? 'N' : p == Parity::odd ? 'O' : 'E'; }

std::string_view stop_text(StopBits s) {
  return s == StopBits::one ? "1" : s == StopBits::two ? "2" : "1.5";
}

speed_t speed_code(unsigned baud) {
  switch (baud) {
    case 300:
      return B300;
    case 600:
      return B600;
    case 1200:
      return B1200;
    case 2400:
      return B2400;
    case 4800:
      return B4800;
    case 9600:
      return B9600;
    case 19200:
      return B19200;
    case 38400:
      return B38400;
    case 57600:
      return B57600;
    case 115200:
      return B115200;
    case 230400:
      return B230400;
    case 460800:
      return B460800;
    case 921600:
      return B921600;
    default:
      return B0;
  }
}

tcflag_t size_flag(unsigned bits) {
  return bits == 5 ? CS5 : bits == 6 ? CS6 : bits == 7 ? CS7 : CS8;
}

// Unix98 pseudo-terminal slaves have majors 136..143 (Documentation/admin-guide/devices.txt).
bool is_pseudo_terminal(int fd) {
  struct stat st {};
  return fstat(fd, &st) == 0 && S_ISCHR(st.st_mode) && major(st.st_rdev) >= 136 &&
         major(st.st_rdev) <= 143;
}

// The process holding a flock(2) on the file `st` names, from /proc/locks, e.g.
// "1: FLOCK  ADVISORY  WRITE 4242 00:18:3 0 EOF" (pid, then the file system's device in hex and
// the inode); "pid 4242 (daq)", or empty when no process holds one (or /proc is not there).
std::string lock_holder(const struct stat& st) {
  const std::string file =
      fmt::format("{:02x}:{:02x}:{}", major(st.st_dev), minor(st.st_dev), st.st_ino);
  std::ifstream locks("/proc/locks");
  for (std::string line; std::getline(locks, line);) {
    std::istringstream in(line);
    std::string number, kind, mode, access, pid, id;
    in >> number >> kind >> mode >> access >> pid >> id;  // a waiter's line has "->": no match
    if (kind != "FLOCK" || id != file) continue;
    std::string name;
    std::getline(std::ifstream("/proc/" + pid + "/comm"), name);
    // The name is whatever the process chose to call itself: escaped for the terminal.
    return name.empty() ? fmt::format("pid {}", pid)
                        : fmt::format("pid {} ({})", pid, cal::text::terminal_safe(name));
  }
  return {};
}

std::string busy_text(const std::string& holder) {
  // Two readers of one serial port each get part of its bytes: neither sees whole lines.
  return fmt::format(
      "busy: {} has the port open; close it first (two programs would each get "
      "part of its bytes)",
      holder.empty() ? "another program" : holder);
}

// Takes the port for this process alone, as picocom and pyserial's exclusive mode do: an
// exclusive flock (which a second caldaq, picocom or pyserial asks for too, and which goes with
// the holder's descriptor, even on a crash). Real ports are also set TIOCEXCL, so that a
// program that does not ask for a lock (cat, screen, a modem manager's probe) cannot open the
// port either; not pseudo-terminals, where the flag outlives the holder's descriptor (the
// pair's terminal stays while the other side is open: a crash would leave a twin's port
// refused to every later open). Returns what went wrong, empty when the port is ours.
std::string lock_port(int fd, bool pty) {
  // Asio opens without O_CLOEXEC: a program daq starts (Chromium printing a report) would
  // inherit the port, and with it the lock, and keep both after daq closed the port.
  ::fcntl(fd, F_SETFD, FD_CLOEXEC);
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    if (errno != EWOULDBLOCK) return fmt::format("cannot lock: {}", std::strerror(errno));
    struct stat st {};
    return busy_text(::fstat(fd, &st) == 0 ? lock_holder(st) : std::string());
  }
  if (!pty) ::ioctl(fd, TIOCEXCL);  // best effort: the flock is the lock caldaq relies on
  return {};
}

// Sets the whole line discipline in one tcsetattr (raw mode, speed, framing, flow control)
// and reads it back: termios reports success even when a driver ignores a flag, so the read
// back is the only way to know. Done with termios directly rather than Asio's serial_port
// options, which set one flag per call (Boost 1.74 refuses CS7 on a pty).
//
// Pseudo-terminals carry whole bytes: the kernel forces CS8 and clears PARENB on them, and on
// current kernels (seen on 6.x) a second tcsetattr asking for 7E1 again fails with EINVAL, so
// the PTU300's 4800 7E1 worked on the first open of a twin's pty and failed on every reopen
// (the next run, every reconnection). On a pty the framing is therefore asked as what the pty
// carries (8 data bits, no parity); the speed and flow control as configured. Real ports get
// exactly the configured framing, read back and checked as before.
std::string configure(int fd, const SerialSettings& s) {
  const speed_t speed = speed_code(s.baud);
  if (speed == B0) return fmt::format("baud rate {} is not a standard rate", s.baud);
  if (s.stop_bits == StopBits::one_point_five)
    return "1.5 stop bits cannot be set through POSIX termios";
  termios tio{};
  if (tcgetattr(fd, &tio) != 0) return fmt::format("not a serial port: {}", std::strerror(errno));
  const bool pty = is_pseudo_terminal(fd);
  cfmakeraw(&tio);
  cfsetispeed(&tio, speed);
  cfsetospeed(&tio, speed);
  tio.c_cflag &= ~static_cast<tcflag_t>(CSIZE | PARENB | PARODD | CSTOPB | CRTSCTS);
  tio.c_cflag |= (pty ? CS8 : size_flag(s.data_bits)) | CREAD | CLOCAL;
  if (!pty && s.parity != Parity::none) tio.c_cflag |= PARENB;
  if (!pty && s.parity == Parity::odd) tio.c_cflag |= PARODD;
  if (s.stop_bits == StopBits::two) tio.c_cflag |= CSTOPB;
  if (s.flow == FlowControl::hardware) tio.c_cflag |= CRTSCTS;
  tio.c_iflag &= ~static_cast<tcflag_t>(IXON | IXOFF | IXANY);
  if (s.flow == FlowControl::software) tio.c_iflag |= IXON | IXOFF;
  tio.c_cc[VMIN] = 1;
  tio.c_cc[VTIME] = 0;
  if (tcsetattr(fd, TCSANOW, &tio) != 0)
    return fmt::format("cannot set {}: {}", format_serial_settings(s), std::strerror(errno));
  termios back{};
  tcgetattr(fd, &back);
  if (cfgetispeed(&back) != speed) return fmt::format("the port refused baud rate {}", s.baud);
  const tcflag_t framing = CSIZE | PARENB | PARODD | CSTOPB;
  if (!pty && (back.c_cflag & framing) != (tio.c_cflag & framing))
    return fmt::format("the port refused framing {}", format_serial_settings(s));
  return {};
}

class SerialTransport final : public Transport {
 public:
  SerialTransport(asio::io_context& io, SerialSettings settings)
      : io_(io), settings_(std::move(settings)) {}
  ~SerialTransport() override { close(); }

  void open(Handlers handlers) override {
    close();
    session_ = std::make_shared<detail::Session<Port>>(Port(io_), describe());
    boost::system::error_code ec;
    session_->stream().open(settings_.device, ec);
    std::string problem;
    if (ec == boost::system::errc::inappropriate_io_control_operation)
      problem = "not a serial port: " + ec.message();  // asio's open already asks termios
    else if (ec == boost::system::errc::device_or_resource_busy)  // another holder's TIOCEXCL
      problem = busy_text(holder_of(settings_.device));
    else if (ec)
      problem = "cannot open: " + ec.message();
    else
      problem = take(session_->stream().native_handle());
    if (problem.empty()) return session_->start(std::move(handlers), settings_.device);
    // Reported from the event loop, like every other error, so callers see one code path.
    close();
    asio::post(io_, [on_error = std::move(handlers.error), message = describe() + ": " + problem] {
      on_error(Error{ErrorKind::open_failed, message});
    });
  }

  void write(std::span<const std::byte> bytes) override {
    if (session_) session_->write(bytes);
  }
  void close() override {
    if (session_) {
      // TIOCEXCL stays on a terminal while it is open anywhere; the flock goes with the fd.
      if (session_->stream().is_open()) ::ioctl(session_->stream().native_handle(), TIOCNXCL);
      session_->close();
    }
    session_.reset();
  }
  bool is_open() const override { return session_ && session_->active(); }
  std::string describe() const override {
    return "serial " + settings_.device + " " + format_serial_settings(settings_);
  }

 private:
  // Locks the opened port, then sets its line discipline.
  std::string take(int fd) const {
    if (auto problem = lock_port(fd, is_pseudo_terminal(fd)); !problem.empty()) return problem;
    return configure(fd, settings_);
  }
  static std::string holder_of(const std::string& device) {
    struct stat st {};
    return ::stat(device.c_str(), &st) == 0 ? lock_holder(st) : std::string();
  }

  asio::io_context& io_;
  SerialSettings settings_;
  std::shared_ptr<detail::Session<Port>> session_;
};

unsigned parse_unsigned(std::string_view token, std::string_view what, std::string_view text) {
  unsigned value = 0;
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (ec != std::errc{} || end != token.data() + token.size() || token.empty())
    throw InputError(
        fmt::format("serial settings '{}': {} '{}' is not a number", text, what, token));
  return value;
}

// "7E1", "8N1", "8N2", "7O1.5": data bits, parity letter, stop bits.
void parse_frame(std::string_view token, std::string_view text, SerialSettings& s) {
  if (token.size() < 3)
    throw InputError(fmt::format("serial settings '{}': '{}' is not like 8N1", text, token));
  s.data_bits = parse_unsigned(token.substr(0, 1), "data bits", text);
  if (s.data_bits < 5 || s.data_bits > 8)
    throw InputError(
        fmt::format("serial settings '{}': {} data bits (expected 5..8)", text, s.data_bits));
  switch (token[1]) {
    case 'N':
    case 'n':
      s.parity = Parity::none;
      break;
    case 'E':
    case 'e':
      s.parity = Parity::even;
      break;
    case 'O':
    case 'o':
      s.parity = Parity::odd;
      break;
    default:
      throw InputError(
          fmt::format("serial settings '{}': parity '{}' (expected N, E or O)", text, token[1]));
  }
  const std::string_view stop = token.substr(2);
  if (stop == "1")
    s.stop_bits = StopBits::one;
  else if (stop == "2")
    s.stop_bits = StopBits::two;
  else if (stop == "1.5")
    s.stop_bits = StopBits::one_point_five;
  else
    throw InputError(
        fmt::format("serial settings '{}': stop bits '{}' (expected 1, 1.5 or 2)", text, stop));
}

}  // namespace

SerialSettings parse_serial_settings(std::string_view text, SerialSettings base) {
  std::vector<std::string_view> tokens;
  for (std::size_t i = 0; i < text.size();) {
    const std::size_t start = text.find_first_not_of(' ', i);
    if (start == std::string_view::npos) break;
    const std::size_t end = std::min(text.find(' ', start), text.size());
    tokens.push_back(text.substr(start, end - start));
    i = end;
  }
  if (tokens.size() < 2 || tokens.size() > 3)
    throw InputError(fmt::format(
        "serial settings '{}': expected 'BAUD FRAME [FLOW]', e.g. '4800 7E1' or '9600 8N1 rtscts'",
        text));
  base.baud = parse_unsigned(tokens[0], "baud rate", text);
  parse_frame(tokens[1], text, base);
  base.flow = FlowControl::none;
  if (tokens.size() == 3) {
    if (tokens[2] == "rtscts")
      base.flow = FlowControl::hardware;
    else if (tokens[2] == "xonxoff")
      base.flow = FlowControl::software;
    else if (tokens[2] != "none")
      throw InputError(
          fmt::format("serial settings '{}': flow control '{}' (expected none, rtscts or xonxoff)",
                      text, tokens[2]));
  }
  return base;
}

std::string format_serial_settings(const SerialSettings& s) {
  std::string text = fmt::format("{} {}{}{}", s.baud, s.data_bits, parity_letter(s.parity),
                                 stop_text(s.stop_bits));
  if (s.flow == FlowControl::hardware) text += " rtscts";
  if (s.flow == FlowControl::software) text += " xonxoff";
  return text;
}

std::unique_ptr<Transport> make_serial(asio::io_context& io, SerialSettings settings) {
  return std::make_unique<SerialTransport>(io, std::move(settings));
}

std::string_view to_string(ErrorKind kind) {
  using enum ErrorKind;
  // clang-format off
  static constexpr EnumName<ErrorKind> kNames[] = {
      {open_failed, "open failed"}, {read_failed, "read failed"}, {write_failed, "write failed"},
      {closed_by_peer, "closed by peer"}, {timeout, "timeout"}};
  // clang-format on
  static_assert(cal::names_every_value(kNames));
  return name_of(kNames, kind, "unknown");
}

}  // namespace cal::drivers::transport
