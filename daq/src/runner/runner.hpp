#pragma once
// The one runner that every kind of run is (linear_run.hpp: positioning, straightness, angular,
// roll; circle_run.hpp: a ballbar test or set): the run store and the batch writer of its raw
// readings, the 10 Hz tick (the writer's age check and the kind's live state), the run's time
// origin, and how a run stops. A kind adds its instruments, stages and results through the
// hooks. Included only by the kinds' sources (Asio's timer, the store).
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "cal/daq/config.hpp"
#include "cal/drivers/codec/common.hpp"
#include "cal/drivers/loop_time.hpp"
#include "cal/storage/store.hpp"
#include "cal/storage/writer.hpp"

namespace boost::asio {
class io_context;
}

namespace daq {

// What an instrument's codec refused (a malformed frame, a sensor's "did not answer" code),
// told to the run's events: an operator must see why a device gives no values, not only a
// counter. The first kListedCodecErrors of an instrument are told in full; then one line says
// the rest are only counted (a stream of garbage must not bury every other event).
inline constexpr int kListedCodecErrors = 3;
std::function<void(const cal::drivers::codec::CodecError&)> codec_errors_as_events(
    std::string instrument, std::function<void(const std::string&)> event);

class Runner {
 public:
  Runner(boost::asio::io_context& io, std::filesystem::path database,
         cal::storage::StoreOptions store_options);
  virtual ~Runner();
  Runner(const Runner&) = delete;
  Runner& operator=(const Runner&) = delete;

  // Ends the run as aborted with `reason`: what the writer holds is flushed and the run is
  // recorded aborted (a store that fails here too is named in the reason). Never throws.
  void abort(const std::string& reason);
  // The kind's destructor: a run still going is stopped ("stopped"); nothing gets through.
  void stop_if_running() noexcept;

  bool running = false, done = false;

 protected:
  // The run store (opened by open_store) and the machine of `c` in it, added when new.
  void open_store();
  std::int64_t machine_id(const cal::daq::Config& c);
  // The batch writer of run `run_id`'s raw readings; its failure aborts the run on the loop.
  void open_writer(std::int64_t run_id);
  // Stores a raw reading; false when the writer had failed (the run is then aborted).
  bool store_reading(const cal::storage::RawReading& r);
  // The run's time origin: this reading's session time is now in UTC (to the delivery delay),
  // so exports can give absolute times.
  void set_time_origin(std::int64_t run_id, std::int64_t time_ns);
  // Every kRunTick: the kind's on_tick, and the writer's age-based flush so a slow or stopped
  // stream is still committed.
  void tick();
  // The end of the run, complete or not: the instruments stopped, the writer closed.
  void end();

  // The kind's part.
  virtual std::int64_t current_run() const = 0;          // the stored run of abort()
  virtual void aborting(const std::string& reason) = 0;  // before: the outcome, the live state
  virtual void aborted(const std::string& reason) = 0;   // after, with what failed besides
  virtual void stop_instruments() = 0;
  virtual void on_tick() {}
  virtual void on_end() {}

  boost::asio::io_context& io;
  std::filesystem::path database;
  cal::storage::StoreOptions store_options;
  std::optional<cal::storage::Store> store;
  std::unique_ptr<cal::storage::BatchWriter> writer;
  cal::drivers::Timer timer;  // on the loop's time: simulated in a simulated session
  // Handlers posted from the writer's thread run only while the run exists.
  std::shared_ptr<bool> alive = std::make_shared<bool>(true);
};

}  // namespace daq
