#pragma once
// Transports move bytes and report errors; nothing more (see ../shared/DESIGN.md). Every
// protocol detail lives in the codecs. A transport runs on the caller's asio::io_context: its
// handlers are called from that context's thread, so instruments need no locks.
//
// Boost.Asio stays out of this header (it is included by every instrument): io_context is
// only forward-declared here, and the factories live in the .cpp files.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>

namespace boost::asio {
class io_context;
}

namespace cal::drivers::transport {

enum class ErrorKind {
  open_failed,     // the device or host could not be opened / connected
  read_failed,     // an I/O error while reading (e.g. the USB adapter was unplugged)
  write_failed,    // an I/O error while writing
  closed_by_peer,  // orderly end of stream (TCP FIN, pty master closed, end of a replay)
  timeout,         // connect or read timeout
};
std::string_view to_string(ErrorKind kind);

struct Error {
  ErrorKind kind = ErrorKind::read_failed;
  std::string message;  // names the device ("serial /dev/ttyUSB0: ...") and the OS error text
};

class Transport {
 public:
  using DataHandler = std::function<void(std::span<const std::byte>)>;
  using ErrorHandler = std::function<void(const Error&)>;

  virtual ~Transport() = default;
  Transport() = default;
  Transport(const Transport&) = delete;
  Transport& operator=(const Transport&) = delete;

  struct Handlers {
    std::function<void()> opened;  // the device is open / the connection is up
    DataHandler data;
    ErrorHandler error;
    // Only replay transports call this: bytes the instrument sent in the recorded session, so
    // that a request/response codec learns what was asked (live transports never call it).
    DataHandler sent;
  };

  // Opens (connects) and starts reading asynchronously. `opened` is called from the event
  // loop once the device can be written to; data then arrive in stream order. The first
  // error ends the session: `error` is called once and nothing follows until the owner opens
  // again (the reconnection policy belongs to the instrument).
  virtual void open(Handlers handlers) = 0;
  void open(DataHandler on_data, ErrorHandler on_error) {
    open(Handlers{{}, std::move(on_data), std::move(on_error)});
  }
  // Queues bytes to send; writes are performed in order. Ignored (with an error report)
  // when the transport is not open.
  virtual void write(std::span<const std::byte> bytes) = 0;
  // Stops reading and releases the device. Safe to call twice; no handler is called after.
  virtual void close() = 0;
  virtual bool is_open() const = 0;
  // "serial /dev/ttyUSB0 4800 7E1 none", "tcp 192.168.1.5:9090": for logs, errors, captures.
  virtual std::string describe() const = 0;
};

// --- Serial (Boost.Asio serial_port; USB-CDC/RS-232 adapters and pseudo-terminals) ---------

enum class Parity { none, odd, even };
enum class StopBits { one, one_point_five, two };
enum class FlowControl { none, software, hardware };

struct SerialSettings {
  std::string device;  // e.g. /dev/ttyUSB0
  unsigned baud = 9600;
  unsigned data_bits = 8;  // 5..8
  Parity parity = Parity::none;
  StopBits stop_bits = StopBits::one;
  FlowControl flow = FlowControl::none;
};

// Parses the usual short form "4800 7E1", "9600 8N1", "115200 8N1 rtscts", "19200 7O2 xonxoff"
// into the line settings of `base` (the device is kept). Throws cal::InputError naming the
// bad part.
SerialSettings parse_serial_settings(std::string_view text, SerialSettings base = {});
// The inverse: "4800 7E1" (plus " rtscts" / " xonxoff" when flow control is on).
std::string format_serial_settings(const SerialSettings& settings);

std::unique_ptr<Transport> make_serial(boost::asio::io_context& io, SerialSettings settings);

// --- TCP client ------------------------------------------------------------------------------

struct TcpSettings {
  std::string host;
  std::uint16_t port = 0;
  std::chrono::milliseconds connect_timeout{3000};
};

std::unique_ptr<Transport> make_tcp(boost::asio::io_context& io, TcpSettings settings);

// --- Transport text, as configurations and capture headers write it ---------------------------

// "tcp HOST:PORT", "serial DEVICE BAUD FRAME [FLOW]", "hid VID:PID" (hex, as lsusb prints it) or
// "hid /dev/hidrawN". Checks the text without opening anything; throws cal::InputError
// "'TEXT': expected ..." naming what is wrong.
void check_transport_text(std::string_view text);
// The transport the text names (checked as above). hid_interface picks the interface of a
// VID:PID device (-1: any).
std::unique_ptr<Transport> make_transport(boost::asio::io_context& io, std::string_view text,
                                          int hid_interface = -1);

}  // namespace cal::drivers::transport
