// The exported times of a run's readings (see reading_times.hpp).
#include "reading_times.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <ctime>
#include <iterator>

namespace daq {

namespace st = cal::storage;

ExportClock::ExportClock(const st::RunReader& store, const st::RunRecord& run,
                         const nlohmann::json& settings) {
  // A series' readings stream in time order, so its first and last are its rows' extremes.
  bool any = false;
  for (const auto& s : store.series(run.id)) {
    streams_[{s.device, s.channel, s.quantity}].period_ns =
        s.count > 1 ? static_cast<double>(s.last_ns - s.first_ns) / static_cast<double>(s.count - 1)
                    : 0.0;
    if (s.count > 0 && (!any || s.first_ns < t0_ns_)) t0_ns_ = s.first_ns, any = true;
  }
  // A ballbar's samples come at the programmed rate (device 3 of a circle run).
  if (run.kind == "circle" && settings.is_object() && settings.value("sample_rate_hz", 0.0) > 0)
    for (auto& [k, s] : streams_)
      if (std::get<0>(k) == 3) s.period_ns = 1e9 / settings.value("sample_rate_hz", 1.0);
  if (run.origin_session_ns && run.origin_unix_ns) {
    t0_ns_ = *run.origin_session_ns;
    unix0_ns_ = *run.origin_unix_ns;
  }
}

void ExportClock::spread(Stream& s, const std::vector<st::RawReading>& group,
                         std::vector<double>& times) {
  const double read = static_cast<double>(group.front().time_ns);
  const auto n = group.size();
  double p = s.period_ns;
  if (s.has_last && read - static_cast<double>(n - 1) * p <= s.last_ns)
    p = (read - s.last_ns) / static_cast<double>(n);
  times.resize(n);
  for (std::size_t k = 0; k < n; ++k) times[k] = read - static_cast<double>(n - 1 - k) * p;
  s.last_ns = read;
  s.has_last = true;
}

std::optional<std::int64_t> ExportClock::unix_ns(double session_ns) const {
  if (!unix0_ns_) return std::nullopt;
  // std::llround (half away from zero) without its libm call, which was 5 % of an export: the
  // truncation and the fraction left are exact for a double, and above 2^52 a double is whole.
  const double x = session_ns - static_cast<double>(t0_ns_);
  if (!(std::abs(x) < 0x1p52)) return *unix0_ns_ + static_cast<std::int64_t>(std::llround(x));
  auto whole = static_cast<std::int64_t>(x);
  const double fraction = x - static_cast<double>(whole);
  if (fraction >= 0.5) ++whole;
  if (fraction <= -0.5) --whole;
  return *unix0_ns_ + whole;
}

std::string ExportClock::utc(double session_ns) const { return std::string(utc_view(session_ns)); }

std::string_view ExportClock::utc_view(double session_ns) const {
  const auto unix = unix_ns(session_ns);
  if (!unix) return {};
  const std::int64_t ns = *unix;
  const std::int64_t us = ns >= 0 ? ns / 1000 : (ns - 999) / 1000;
  const std::int64_t s = us >= 0 ? us / 1'000'000 : (us - 999'999) / 1'000'000;
  if (s != cached_second_) {
    const auto t = static_cast<std::time_t>(s);
    std::tm tm{};
    gmtime_r(&t, &tm);
    cached_length_ = std::strftime(cached_text_.data(), 32, "%Y-%m-%dT%H:%M:%S", &tm);
    cached_second_ = s;
  }
  // ".uuuuuuZ" after the cached part: six digits of the microseconds in the second.
  char* p = cached_text_.data() + cached_length_;
  p[0] = '.';
  auto micro = us - s * 1'000'000;
  for (int i = 6; i >= 1; --i, micro /= 10) p[i] = static_cast<char>('0' + micro % 10);
  p[7] = 'Z';
  return {cached_text_.data(), cached_length_ + 8};
}

void ExportRows::find_stream(const st::RawReading& r) {
  const StreamKey key = key_of(r);
  const auto it = std::lower_bound(pending_.begin(), pending_.end(), key,
                                   [](const Pending& e, const StreamKey& k) { return e.key < k; });
  const auto at =
      it == pending_.end() || it->key != key
          ? pending_.insert(it, Pending{key, packed_key(r), &clock_.stream(key), {}, {}})
          : it;
  last_ = static_cast<std::size_t>(at - pending_.begin());  // after the insertion
}

}  // namespace daq
