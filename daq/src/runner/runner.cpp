// What every kind of run shares (see runner.hpp).
#include "runner.hpp"

#include <fmt/format.h>

#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>
#include <chrono>

#include "run_writer.hpp"

namespace daq {

std::function<void(const cal::drivers::codec::CodecError&)> codec_errors_as_events(
    std::string instrument, std::function<void(const std::string&)> event) {
  return [who = std::move(instrument), event = std::move(event),
          told = 0](const cal::drivers::codec::CodecError& e) mutable {
    if (!event || told > kListedCodecErrors) return;
    if (told++ < kListedCodecErrors)
      event(fmt::format("{}: refused at byte {}: {}", who, e.offset, e.description));
    else
      event(
          fmt::format("{}: more refused data; further codec errors are counted, not listed", who));
  };
}

Runner::Runner(boost::asio::io_context& i, std::filesystem::path db,
               cal::storage::StoreOptions options)
    : io(i), database(std::move(db)), store_options(options), timer(i) {}

Runner::~Runner() { *alive = false; }

void Runner::stop_if_running() noexcept {
  try {
    if (!done && running) abort("stopped");
  } catch (...) {
    // abort() does not throw; a display callback (on_live, on_event) might: a destructor
    // must not let it through (std::terminate).
  }
}

void Runner::open_store() { store.emplace(database, store_options); }

std::int64_t Runner::machine_id(const cal::daq::Config& c) {
  if (auto m = store->machine_by_name(c.machine_name)) return m->id;
  return store->add_machine({.name = c.machine_name, .description = c.machine_description});
}

void Runner::open_writer(std::int64_t run_id) {
  writer = std::make_unique<cal::storage::BatchWriter>(database, run_id,
                                                       run_writer_options(io, store_options),
                                                       [this, alive = alive](const std::string& e) {
                                                         boost::asio::post(io, [this, alive, e] {
                                                           if (*alive)
                                                             abort("storage failed: " + e);
                                                         });
                                                       });
}

bool Runner::store_reading(const cal::storage::RawReading& r) {
  try {
    writer->push(r);
  } catch (const std::exception& e) {  // the writer failed earlier (a full disk)
    abort(fmt::format("storage failed: {}", e.what()));
    return false;
  }
  return true;
}

void Runner::set_time_origin(std::int64_t run_id, std::int64_t time_ns) {
  store->set_time_origin(run_id, time_ns,
                         std::chrono::duration_cast<std::chrono::nanoseconds>(
                             std::chrono::system_clock::now().time_since_epoch())
                             .count());
}

void Runner::tick() {
  if (done) return;
  on_tick();
  if (const auto failed = offer_old_batch(writer.get())) return abort(*failed);
  arm_tick(timer, alive, [this] { tick(); });
}

void Runner::abort(const std::string& reason) {
  if (done) return;
  running = false;
  aborting(reason);
  std::string full = reason;
  try {
    if (writer) writer->flush();
  } catch (const std::exception& e) {
    if (reason.find(e.what()) == std::string::npos)
      full += fmt::format(" (and the last batch could not be stored: {})", e.what());
  }
  try {
    if (store) store->finish_run(current_run(), cal::storage::RunStatus::aborted, full);
  } catch (const std::exception& e) {
    full += fmt::format(" (and the run's end could not be stored: {})", e.what());
  }
  aborted(full);
  end();
}

void Runner::end() {
  done = true;
  timer.cancel();
  stop_instruments();
  writer.reset();
  on_end();
}

}  // namespace daq
