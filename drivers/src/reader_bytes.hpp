#pragma once
// Private to drivers/: simulated time's accounting of the bytes a twin sends to one driver, a
// reader that may go away (cal/drivers/loop_time.hpp counts bytes in flight; this says whose).
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace boost::asio {
class execution_context;
}

namespace cal::drivers::detail {

// The bytes a twin sends to one driver's end of its channel, named alike by both (the
// pseudo-terminal's path; "tcp:PORT" by the driver's port), count in flight on the loop's
// VirtualTime until that driver reads them: the clock waits for them. Once the driver has
// closed, what it left unread and what is sent to it later no longer count: nobody will read
// them, and the clock would wait VirtualTime::kSettle (2 s of wall time) for them, each time
// `daq serve --simulate` closed its monitors while a twin's answer was on its way (a set-up
// applied, a run started). A reader opened again counts from then on; before it first opens,
// its bytes count (they wait in the channel for it).
//
// The other way, the bytes a driver sends to its twin count under to_twin(the same name), each
// driver's apart: one twin that goes (unplugged, its client dropped) with a driver's request
// unread takes only that driver's bytes off the count, and a twin reading more than was
// counted to it (bytes sent before it opened) cannot take another driver's bytes off. Counted
// globally, a request left unread by a twin that went held the clock for kSettle.
class ReaderBytes {
 public:
  // The accounting of the loop's simulated time; nullptr in real mode.
  static ReaderBytes* of(boost::asio::execution_context& ctx);
  // The name under which a driver's bytes to its twin count: its channel's name (above),
  // marked as the twin's end.
  static std::string to_twin(std::string_view channel) { return "twin<-" + std::string(channel); }

  void written(std::size_t n, std::string_view reader);
  void read(std::size_t n, std::string_view reader);
  void opened(std::string_view reader);
  void closed(std::string_view reader);

  struct Impl;
  explicit ReaderBytes(Impl& impl) : impl_(impl) {}

 private:
  Impl& impl_;
};

}  // namespace cal::drivers::detail
