#pragma once
// The times of a stored run's readings as every export gives them (`daq export` CSV and JSON,
// the Python package's iter_readings; docs/cli.md "daq export"): seconds from the run's start
// and absolute UTC, one per sample. Readings of one device that came in one transport read
// share the time of that read; they are spread back from it by the device's sample period (the
// configured sample rate of a ballbar, else the stream's mean interval over the run), the last
// keeping the read's time. Where that would reach back to the previous read (the reads' own
// timing jitters), the group is spread evenly over the time since the previous read instead:
// times always rise.
#include <array>
#include <cstdint>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

#include "cal/storage/store.hpp"

namespace daq {

using StreamKey = std::tuple<std::uint16_t, std::uint8_t, std::uint8_t>;  // device, channel, q
inline StreamKey key_of(const cal::storage::RawReading& r) {
  return {r.device, r.channel, r.quantity};
}
// The same three numbers in one word, for telling a reading's stream from the last one's with
// one comparison (the tuple's three were about 15 instructions a row of an export, issue 32).
inline std::uint32_t packed_key(const cal::storage::RawReading& r) {
  return r.device | (std::uint32_t{r.channel} << 16) | (std::uint32_t{r.quantity} << 24);
}

class ExportClock {
 public:
  // The periods and the run's start from the series' rows (Store::series: no reading is
  // decoded); `settings` is the run's parsed settings (a circle run's sample_rate_hz).
  ExportClock(const cal::storage::RunReader& store, const cal::storage::RunRecord& run,
              const nlohmann::json& settings);
  // What the spreading knows of one stream (device, channel, quantity).
  struct Stream {
    double period_ns = 0.0;
    double last_ns = 0.0;  // the time of the stream's last group
    bool has_last = false;
  };
  // The stream's state (a stream without stored series: period 0); stays valid as long as the
  // clock.
  Stream& stream(const StreamKey& key) { return streams_[key]; }
  // Session times (ns, fractional) into `times` of a group of one stream's readings sharing one
  // stored time, in order; remembers the group's time for the stream's next group.
  static void spread(Stream& s, const std::vector<cal::storage::RawReading>& group,
                     std::vector<double>& times);
  // The same for a group of one reading (most groups: a reading per stored time), which keeps
  // its stored time (read - 0 x period); returns it.
  static double spread_one(Stream& s, std::int64_t time_ns) {
    s.last_ns = static_cast<double>(time_ns);
    s.has_last = true;
    return s.last_ns;
  }
  // Seconds from the run's start: the nanoseconds / 10^9, one correctly rounded division, so
  // a whole number of nanoseconds gives its exact decimal's own double (x 1e-9, two
  // roundings, gave 41 % of a 100 us grid's times one ulp off it: issue 32).
  double seconds(double session_ns) const { return since_origin_ns(session_ns) / 1e9; }
  // The nanoseconds that seconds() divides (exact for a whole session_ns below 2^53).
  double since_origin_ns(double session_ns) const {
    return session_ns - static_cast<double>(t0_ns_);
  }
  // Unix ns of a session time (rounded to the ns), or nullopt when the run has no time origin
  // (stored before it was recorded, or imported).
  std::optional<std::int64_t> unix_ns(double session_ns) const;
  // ISO 8601 UTC with microseconds (unix_ns truncated), or "" without a time origin.
  std::string utc(double session_ns) const;
  // The same text, valid until the next call (no string per reading). The date and time of day
  // are formatted once a second: an export's rows share them ten thousand at a time, and
  // gmtime and strftime per row were a fifth of its time.
  std::string_view utc_view(double session_ns) const;
  bool has_utc() const { return unix0_ns_.has_value(); }

 private:
  std::map<StreamKey, Stream> streams_;
  std::int64_t t0_ns_ = 0;
  std::optional<std::int64_t> unix0_ns_;
  mutable std::int64_t cached_second_ = std::numeric_limits<std::int64_t>::min();
  mutable std::array<char, 40> cached_text_{};  // "YYYY-MM-DDTHH:MM:SS.uuuuuuZ"
  mutable std::size_t cached_length_ = 0;       // of the date and time of day
};

// One exported reading (after the time spreading).
struct ExportRow {
  cal::storage::RawReading r;
  double session_ns = 0;
  std::uint64_t tag = 0;  // the caller's, given to ExportRows::add with the reading
};

// Readings in the store's order in, rows with their spread times out: a group of one stream's
// readings with one stored time is held until a later time shows it is complete; then every
// group of that time goes out, stream by stream (device, channel, quantity). The memory is one
// stored time's readings.
class ExportRows {
 public:
  explicit ExportRows(ExportClock& clock) : clock_(clock) {}
  // Hands to `emit` (called with an ExportRow) the rows that `r` completes; `tag` goes out with
  // r's row (the caller's number for what it computed from r in the store's order, e.g. its
  // compensation). A template, so that an export's row goes from the store's batch to its text
  // without a vector between them (the rows' vector, pushed and read back per reading, was a
  // sixth of an export: issue 32).
  template <class Emit>
  void add_each(const cal::storage::RawReading& r, Emit&& emit, std::uint64_t tag = 0) {
    // Readings come in time order: the groups are complete when a later time arrives.
    if (held_ != 0 && r.time_ns != current_) flush_each(emit);
    current_ = r.time_ns;
    // A second reading of this time: the one held apart goes into its stream's group first
    // (last_ is still its entry: find_stream may insert before it).
    if (held_ == 1) {
      pending_[last_].group.push_back(one_);
      pending_[last_].tags.push_back(one_tag_);
    }
    if (last_ >= pending_.size() || pending_[last_].packed != packed_key(r)) find_stream(r);
    if (held_ == 0) {  // most readings: held apart, no vector pushed and cleared for it
      one_ = r;
      one_tag_ = tag;
      held_ = 1;
      return;
    }
    pending_[last_].group.push_back(r);
    pending_[last_].tags.push_back(tag);
    ++held_;
  }
  // The same for a batch of readings in the store's order (tags 0). A reading alone at its
  // time (the next one in the batch has another time, and none of its own time is held), the
  // usual one, goes out at once: not held, copied and handed on at the next reading (that way
  // was a tenth of an export's instructions, issue 32). The rest as add_each.
  template <class Emit>
  void add_batch(std::span<const cal::storage::RawReading> batch, Emit&& emit) {
    const std::size_t n = batch.size();
    for (std::size_t i = 0; i < n; ++i) {
      const auto& r = batch[i];
      if (i + 1 == n || batch[i + 1].time_ns == r.time_ns ||
          (held_ != 0 && r.time_ns == current_)) {
        add_each(r, emit);
        continue;
      }
      if (held_ != 0) flush_each(emit);  // the readings of an earlier time
      if (last_ >= pending_.size() || pending_[last_].packed != packed_key(r)) find_stream(r);
      emit(ExportRow{r, ExportClock::spread_one(*pending_[last_].stream, r.time_ns), 0});
    }
  }
  // Hands on the rows still held (after the last reading).
  template <class Emit>
  void finish_each(Emit&& emit) {
    flush_each(emit);
  }
  // The same into a vector: appends to `out`.
  void add(const cal::storage::RawReading& r, std::vector<ExportRow>& out, std::uint64_t tag = 0) {
    add_each(
        r, [&](const ExportRow& x) { out.push_back(x); }, tag);
  }
  void finish(std::vector<ExportRow>& out) {
    finish_each([&](const ExportRow& x) { out.push_back(x); });
  }

 private:
  struct Pending {
    StreamKey key;
    std::uint32_t packed;  // packed_key of its readings
    ExportClock::Stream* stream;
    std::vector<cal::storage::RawReading> group;
    std::vector<std::uint64_t> tags;
  };
  // Sets last_ to r's stream's entry, made if it is new.
  void find_stream(const cal::storage::RawReading& r);
  template <class Emit>
  void flush_each(Emit& emit) {
    if (held_ == 1) {  // the usual case, a reading per stored time: held apart in one_
      held_ = 0;
      emit(ExportRow{one_, ExportClock::spread_one(*pending_[last_].stream, one_.time_ns),
                     one_tag_});
      return;
    }
    held_ = 0;
    for (auto& e : pending_) {
      if (e.group.empty()) continue;
      if (e.group.size() == 1) {
        emit(ExportRow{e.group[0], ExportClock::spread_one(*e.stream, e.group[0].time_ns),
                       e.tags[0]});
      } else {
        ExportClock::spread(*e.stream, e.group, times_);
        for (std::size_t i = 0; i < e.group.size(); ++i)
          emit(ExportRow{e.group[i], times_[i], e.tags[i]});
      }
      e.group.clear();
      e.tags.clear();
    }
  }
  ExportClock& clock_;
  std::vector<Pending> pending_;  // one per stream seen, by key (a handful: found by a scan)
  std::size_t last_ = 0;          // the entry of the last reading (most follow their stream)
  std::size_t held_ = 0;          // readings held (1: only one_, of the stream at last_)
  cal::storage::RawReading one_;  // the only reading of the current time, while held_ is 1
  std::uint64_t one_tag_ = 0;
  std::vector<double> times_;
  std::int64_t current_ = 0;
};

}  // namespace daq
