// Capture throughput: write, then read back at full speed, the capture of a 10 kHz
// interferometer streaming ASCII lines (by default one hour: 36,000,000 readings).
//
// The bytes are modelled as the transport sees them: every 1 ms the serial/TCP read returns
// one chunk of 10 lines of 24 bytes ("1 +000123.456789012 mm\r\n"), so an hour is 3,600,000
// records of 240 bytes. The chunks are drawn from a pre-formatted pool so that the timing is
// the capture code's, not the number formatting's. The writer flushes every 50 records
// (50 ms of recorded time), as `daq` flushes its capture every 50 ms of the event loop: this
// makes smaller blocks than the 64 KiB limit and is the pessimistic, realistic case.
//
// Usage: replay_bench [--seconds N] [--flush-every RECORDS] [--dir DIR]
// Prints time, MB/s (10^6 bytes of file per second) and the peak RSS (getrusage ru_maxrss).
#include <fmt/format.h>
#include <sys/resource.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "cal/replay/capture.hpp"

namespace {

using Clock = std::chrono::steady_clock;

struct Options {
  long seconds = 3600;
  long flush_every = 50;
  std::filesystem::path dir = "/tmp";
};

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string_view key = argv[i];
    const char* value = argv[i + 1];
    if (key == "--seconds")
      o.seconds = std::atol(value);
    else if (key == "--flush-every")
      o.flush_every = std::atol(value);
    else if (key == "--dir")
      o.dir = value;
    else
      throw std::invalid_argument(fmt::format("unknown option {}", key));
  }
  if (o.seconds <= 0 || o.flush_every <= 0)
    throw std::invalid_argument("--seconds and --flush-every must be > 0");
  return o;
}

// 1000 distinct chunks of 10 lines of 24 bytes: a slow sine of ±150 mm with a fine ripple.
std::vector<std::vector<std::byte>> chunk_pool() {
  std::vector<std::vector<std::byte>> pool;
  for (int c = 0; c < 1000; ++c) {
    std::string s;
    for (int k = 0; k < 10; ++k) {
      const double x_mm = 150.0 * std::sin(0.00001 * (c * 10 + k)) + 1e-6 * ((c * 7 + k) % 13);
      s += fmt::format("1 {:+017.9f} mm\r\n", x_mm);
    }
    const auto* p = reinterpret_cast<const std::byte*>(s.data());
    pool.emplace_back(p, p + s.size());
  }
  return pool;
}

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

long peak_rss_kib() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss;  // KiB on Linux
}

int run(const Options& o) {
  const auto pool = chunk_pool();
  const auto path = o.dir / fmt::format("caldaq-bench-{}.cdq", ::getpid());
  const long records = o.seconds * 1000;
  std::uint64_t payload = 0;

  const auto w0 = Clock::now();
  {
    cal::replay::CaptureWriter w(path, R"({"format": "caldaq.capture-header.v1", "bench": true})");
    for (long i = 0; i < records; ++i) {
      const auto& chunk = pool[static_cast<std::size_t>(i % 1000)];
      w.record(i * 1'000'000, 0, cal::replay::RecordKind::received, chunk);
      payload += chunk.size();
      if ((i + 1) % o.flush_every == 0) w.flush();
    }
    w.close();
  }
  const double write_s = seconds_since(w0);
  const auto file_bytes = std::filesystem::file_size(path);
  const long rss_after_write = peak_rss_kib();

  const auto r0 = Clock::now();
  std::uint64_t read_payload = 0, read_records = 0;
  bool damaged = false;
  {
    cal::replay::CaptureReader r(path);
    while (auto rec = r.next()) {
      read_payload += rec->bytes.size();
      ++read_records;
    }
    damaged = r.damage().has_value();
  }
  const double read_s = seconds_since(r0);
  std::filesystem::remove(path);

  const double mb = static_cast<double>(file_bytes) / 1e6;
  fmt::print("capture of {} s of a 10 kHz interferometer: {} records, {} readings\n", o.seconds,
             records, records * 10);
  fmt::print("  payload {:.1f} MB, file {:.1f} MB (overhead {:.1f} %), flush every {} records\n",
             static_cast<double>(payload) / 1e6, mb,
             100.0 * (static_cast<double>(file_bytes) / static_cast<double>(payload) - 1.0),
             o.flush_every);
  fmt::print("  write: {:.3f} s, {:.0f} MB/s, {:.2f} M records/s\n", write_s, mb / write_s,
             static_cast<double>(records) / write_s / 1e6);
  fmt::print("  read:  {:.3f} s, {:.0f} MB/s, {:.2f} M records/s\n", read_s, mb / read_s,
             static_cast<double>(read_records) / read_s / 1e6);
  fmt::print("  peak RSS: {} KiB after writing, {} KiB after reading\n", rss_after_write,
             peak_rss_kib());
  if (damaged || read_records != static_cast<std::uint64_t>(records) || read_payload != payload) {
    fmt::print(stderr, "read back {} records / {} bytes, damaged: {}\n", read_records, read_payload,
               damaged);
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(parse(argc, argv));
  } catch (const std::exception& e) {
    fmt::print(stderr, "replay_bench: {}\n", e.what());
    return 2;
  }
}
