// MTConnect SHDR codec (see shdr/codec.hpp).
#include "shdr/codec.hpp"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <utility>

#include "cal/analysis/error.hpp"

namespace cal::drivers::codec {
namespace {

// Days from 1970-01-01 to a proleptic Gregorian date (Howard Hinnant's days_from_civil).
std::int64_t days_from_civil(std::int64_t y, unsigned m, unsigned d) {
  y -= m <= 2;
  const std::int64_t era = (y >= 0 ? y : y - 399) / 400;
  const auto yoe = static_cast<unsigned>(y - era * 400);
  const unsigned doy = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;
  const unsigned doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + static_cast<std::int64_t>(doe) - 719468;
}

}  // namespace

std::optional<std::int64_t> parse_iso8601_utc_ns(std::string_view s) {
  if (s.ends_with('Z')) s.remove_suffix(1);
  if (s.size() < 19 || s[4] != '-' || s[7] != '-' || s[10] != 'T' || s[13] != ':' || s[16] != ':')
    return std::nullopt;
  const auto y = parse_integer<int>(s.substr(0, 4));
  const auto mo = parse_integer<unsigned>(s.substr(5, 2)),
             d = parse_integer<unsigned>(s.substr(8, 2));
  const auto h = parse_integer<unsigned>(s.substr(11, 2)),
             mi = parse_integer<unsigned>(s.substr(14, 2));
  const auto sec = parse_integer<unsigned>(s.substr(17, 2));
  // Years 1970..2261: Unix nanoseconds in an int64 reach 2262-04-11.
  if (!y || !mo || !d || !h || !mi || !sec || *y < 1970 || *y > 2261 || *mo < 1 || *mo > 12 ||
      *d < 1 || *d > 31 || *h > 23 || *mi > 59 || *sec > 60)
    return std::nullopt;
  std::int64_t frac_ns = 0;
  if (s.size() > 19) {
    if (s[19] != '.' || s.size() == 20 || s.size() > 29) return std::nullopt;
    const auto digits = s.substr(20);
    if (digits.find_first_not_of("0123456789") != std::string_view::npos) return std::nullopt;
    const auto f = parse_integer<std::int64_t>(digits);
    if (!f) return std::nullopt;
    frac_ns = *f;
    for (std::size_t i = digits.size(); i < 9; ++i) frac_ns *= 10;
  }
  const std::int64_t secs =
      days_from_civil(*y, *mo, *d) * 86400 + *h * 3600 + *mi * 60 + static_cast<std::int64_t>(*sec);
  return secs * 1'000'000'000 + frac_ns;
}

ShdrCodec::ShdrCodec(ShdrConfig config)
    : config_(std::move(config)), splitter_(config_.max_line_bytes) {
  for (const auto& [key, axis] : config_.keys)
    if (axis < 0 || axis > 2)
      throw InputError(fmt::format("SHDR key '{}': axis {} (expected 0, 1 or 2)", key, axis));
}

void ShdrCodec::do_feed(std::span<const std::byte> bytes, std::vector<PositionFrame>& frames,
                        std::vector<CodecError>& errors) {
  splitter_.feed(
      bytes, [&](std::string_view line, std::uint64_t off) { decode(line, off, frames, errors); },
      [&](std::uint64_t off) {
        report(errors, ErrorKind::overlong_line, off,
               fmt::format("SHDR: line longer than {} bytes", config_.max_line_bytes));
      });
}

std::vector<std::string> shdr_tokens(std::string_view line) {
  const auto space = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; };
  std::vector<std::string> tokens;
  std::size_t i = 0;
  while (true) {
    while (i < line.size() && space(line[i])) ++i;
    const std::size_t start = i;
    std::string token;
    bool quoted = false;
    if (i < line.size() && line[i] == '"') {
      // Up to a closing quote followed (after spaces) by '|' or the end; '\' escapes.
      std::string body;
      std::size_t j = i + 1;
      for (; j < line.size(); ++j) {
        if (line[j] == '\\' && j + 1 < line.size()) {
          body.push_back(line[++j]);
          continue;
        }
        if (line[j] == '"') {
          std::size_t k = j + 1;
          while (k < line.size() && space(line[k])) ++k;
          if (k == line.size() || line[k] == '|') break;
        }
        if (line[j] == '|') {  // unterminated: a plain token after all
          j = line.size();
          break;
        }
        body.push_back(line[j]);
      }
      if (j < line.size()) {
        quoted = true;
        token = std::move(body);
        i = line.find('|', j);
        if (i == std::string_view::npos) i = line.size();
      }
    }
    if (!quoted) {
      i = std::min(line.find('|', start), line.size());
      std::size_t end = i;
      while (end > start && space(line[end - 1])) --end;
      token = std::string(line.substr(start, end - start));
    }
    tokens.push_back(std::move(token));
    if (i >= line.size()) break;
    ++i;                                          // past the '|'
    if (i == line.size()) tokens.emplace_back();  // a terminal '|': one more, empty token
    if (i >= line.size()) break;
  }
  return tokens;
}

void ShdrCodec::heartbeat(std::string_view line) {
  // As the agent's connector: "* PONG" starts heartbeats when a number follows it.
  if (line.starts_with("* PONG")) {
    ++pongs_;
    const auto t = split_whitespace(line);
    if (t.size() >= 3)
      if (auto ms = parse_integer<std::int64_t>(t[2]); ms && *ms > 0) pong_timeout_ms_ = *ms;
    return;
  }
  if (line.starts_with("* PING")) {
    ++pings_;
    return;
  }
  ++commands_;  // "* key: value" and "*key:value": adapter commands and metadata
  last_command_ = std::string(line.substr(0, 80));
}

void ShdrCodec::decode(std::string_view line, std::uint64_t offset,
                       std::vector<PositionFrame>& frames, std::vector<CodecError>& errors) {
  while (!line.empty() && (line.back() == ' ' || line.back() == '\t')) line.remove_suffix(1);
  if (line.empty()) return;
  if (!multiline_tag_.empty()) {  // the body of a multi-line value (an asset document)
    if (line == multiline_tag_) multiline_tag_.clear();
    return;
  }
  if (line.front() == '*') return heartbeat(line);
  if (!is_printable_ascii(line))
    return report(errors, ErrorKind::garbage, offset, "SHDR: non-printable bytes");
  if (const auto at = line.find("--multiline--"); at != std::string_view::npos) {
    multiline_tag_ = std::string(line.substr(at));
    ++assets_;
    return;
  }
  const auto tokens = shdr_tokens(line);
  PositionFrame f;
  std::string_view stamp = tokens.front();
  if (const auto at = stamp.find('@'); at != std::string_view::npos) {
    f.duration_s = parse_number(stamp.substr(at + 1));
    stamp = stamp.substr(0, at);
  }
  if (stamp.find('T') != std::string_view::npos) {
    f.time_unix_ns = parse_iso8601_utc_ns(stamp);
    if (!f.time_unix_ns)
      return report(errors, ErrorKind::malformed, offset,
                    fmt::format("SHDR: '{}' is not a timestamp", stamp.substr(0, 40)));
  } else if (!stamp.empty()) {
    const auto ms = parse_number(stamp);
    if (!ms || !std::isfinite(*ms))
      return report(errors, ErrorKind::malformed, offset,
                    fmt::format("SHDR: '{}' is not a timestamp", stamp.substr(0, 40)));
    if (!relative_origin_ms_) relative_origin_ms_ = *ms;
    f.relative_time_ms = *ms - *relative_origin_ms_;
  }
  // key|value pairs by position, as the agent walks a line (shdr_token_mapper.cpp): a key it
  // does not know skips itself and one value, so a value that happens to equal a key name
  // ("program|Xact") is never taken for a key.
  bool any = false;
  for (std::size_t i = 1; i + 1 < tokens.size(); i += 2) {
    const auto it = config_.keys.find(tokens[i]);
    if (it == config_.keys.end()) {
      if (config_.census) count_key(tokens[i], tokens[i + 1]);
      continue;
    }
    const std::string_view value = tokens[i + 1];
    if (value == "UNAVAILABLE") {  // the control has no value: the position is unknown
      f.unavailable[static_cast<std::size_t>(it->second)] = true;
      any = true;
      continue;
    }
    const auto v = parse_number_scaled(value, config_.metres_per_unit);
    if (!v || !std::isfinite(*v))
      return report(errors, ErrorKind::malformed, offset,
                    fmt::format("SHDR: {} = '{}' is not a number", it->first, value.substr(0, 40)));
    const double m = *v;
    if (std::abs(m) > config_.max_abs_m)
      return report(errors, ErrorKind::out_of_range, offset,
                    fmt::format("SHDR: {} = {} m beyond +/-{} m", it->first, m, config_.max_abs_m));
    f.position_m[static_cast<std::size_t>(it->second)] = m;
    any = true;
  }
  if (any) emit(frames, std::move(f));
}

void ShdrCodec::count_key(std::string_view key, std::string_view value) {
  if (key.empty() || numeric_key_set_.contains(key)) return;
  if (const auto v = parse_number(value); !v || !std::isfinite(*v)) return;
  if (numeric_key_set_.size() >= census_limit) return;  // bounded: a hostile stream
  numeric_key_set_.emplace(key);
  numeric_keys_.emplace_back(key);
}

}  // namespace cal::drivers::codec
