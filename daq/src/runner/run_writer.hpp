#pragma once
// The batch writer's options of a run (linear and circle), so that both commit alike: a batch is
// committed when full or when its oldest reading is old, measured on the loop's time.
#include <fmt/format.h>

#include <boost/asio/io_context.hpp>
#include <boost/system/error_code.hpp>
#include <chrono>
#include <exception>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "cal/drivers/loop_time.hpp"
#include "cal/storage/writer.hpp"

namespace daq {

// On hardware: the default age (200 ms) on the steady clock. In a simulated session (about 100
// times faster than real time) 5 s of its own time, about what 200 ms are on hardware where a
// commit costs an fsync (200 ms of simulated time gave `daq demo` 2,100 fsyncs instead of 240),
// and the batches age on simulated time, so a batch holds the same readings however fast the
// CPU runs the session.
inline cal::storage::WriterOptions run_writer_options(boost::asio::io_context& io,
                                                      cal::storage::StoreOptions store) {
  cal::storage::WriterOptions o{.store = store};
  if (cal::drivers::VirtualTime::of(io)) {
    o.batch_age = std::chrono::milliseconds(5000);
    o.clock = [clock = cal::drivers::loop_clock(io)] {
      return std::chrono::steady_clock::time_point(std::chrono::nanoseconds(clock()));
    };
  }
  return o;
}

// How often a run offers its current batch to the writer's age check (flush_if_old): a slow or
// stopped stream is still committed within about batch_age plus this.
inline constexpr std::chrono::milliseconds kRunTick{100};

// The writer's age check of a run's tick; the reason to abort the run when the writer has
// failed (a full disk) and the run has not heard of it yet.
inline std::optional<std::string> offer_old_batch(cal::storage::BatchWriter* writer) {
  try {
    if (writer) writer->flush_if_old();
  } catch (const std::exception& e) {
    return fmt::format("storage failed: {}", e.what());
  }
  return std::nullopt;
}

// Arms the run's next tick, kRunTick from now on the loop's time; `tick` runs only while the
// run's `alive` flag holds: a wait that has already fired still runs its handler with success
// after cancel() or the timer's end, when the run may be gone.
inline void arm_tick(cal::drivers::Timer& timer, std::shared_ptr<const bool> alive,
                     std::function<void()> tick) {
  timer.expires_after(kRunTick);
  timer.async_wait(
      [alive = std::move(alive), tick = std::move(tick)](const boost::system::error_code& ec) {
        if (!ec && *alive) tick();
      });
}

}  // namespace daq
