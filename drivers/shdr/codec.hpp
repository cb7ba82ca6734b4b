#pragma once
// MTConnect SHDR, a machine position feed for the position-assisted trigger: the lines an
// adapter sends the agent (TCP, port 7878 by default), read as the MTConnect C++ agent reads
// them (github.com/mtconnect/cppagent: source/adapter/shdr/connector.cpp, shdr_adapter.cpp,
// pipeline/shdr_tokenizer.hpp, pipeline/timestamp_extractor.hpp):
//  - a line is everything up to LF, right-trimmed (so CR LF works); blank lines are skipped;
//  - "* PONG <ms>" answers the agent's "* PING" (heartbeats, see shdr/instrument.hpp); other
//    lines starting with '*' are commands ("* shdrVersion: 2", "*adapterVersion:1.0"), not data;
//  - a line holding "--multiline--TAG" starts a multi-line value (an asset document) that ends
//    at a line equal to "--multiline--TAG";
//  - tokens are separated by '|' and trimmed; a token in double quotes may hold '|' and '"'
//    escaped with a backslash (an unterminated quote makes the token plain text);
//  - the first token is the timestamp: ISO 8601 ("2022-08-08T13:51:34.7167146Z"), empty (the
//    agent stamps it on arrival), or a number without 'T' (relative time, ms); either form may
//    end with "@<duration>";
//  - then key|value pairs, walked by position as the agent's ShdrTokenMapper
//    (pipeline/shdr_token_mapper.cpp) walks them: each item is a key and its values, and a key
//    it does not know is skipped with one value (legacy SHDR, before shdrVersion 2), so a
//    value equal to a key name ("program|Xact|Xact|3": program = "Xact", X = 3) is a value.
//    Items with more values (a condition five, an alarm four, a time series three, a message
//    two) stand on a line of their own in SHDR, and the legacy agent stops reading a line after
//    one of them. This codec has no device model and reads every line as pairs: items after
//    an odd-valued one on the same line (a message, an alarm) would be misaligned, where the
//    legacy agent reads none of them; SHDR adapters do not send such lines (the Okuma
//    recording has none: every line is a timestamp and pairs). "UNAVAILABLE" is no value: the
//    frame marks the axis unavailable (the position is unknown until a value comes).
// Where this codec differs from the agent: a timestamp with 'T' that does not parse (a 13th
// month) or a first token that is neither a time nor a number is refused as malformed; the
// agent silently uses its own clock.
#include <map>
#include <optional>
#include <set>
#include <string>

#include "cal/drivers/codec/common.hpp"
#include "cal/drivers/codec/position.hpp"

namespace cal::drivers::codec {

struct ShdrConfig {
  // Data item key -> axis (0 X, 1 Y, 2 Z), e.g. {"Xact", 0}, {"Yact", 1}, {"Zact", 2}.
  std::map<std::string, int, std::less<>> keys{{"Xact", 0}, {"Yact", 1}, {"Zact", 2}};
  // MTConnect positions are in millimetres (or inches, configured): exact, so a printed value
  // is stored as its decimal in metres, correctly rounded.
  DecimalScale metres_per_unit = kMillimetresToMetres;
  double max_abs_m = 100.0;  // plausibility: beyond it, out_of_range
  std::size_t max_line_bytes = 8192;
  // daq decode: note the keys of the other items whose values are numbers (a hint for a user
  // whose control names its positions otherwise); off in runs.
  bool census = false;
};

class ShdrCodec : public CodecBase<ShdrCodec, PositionFrame> {
 public:
  explicit ShdrCodec(ShdrConfig config = {});
  void do_feed(std::span<const std::byte> bytes, std::vector<PositionFrame>& frames,
               std::vector<CodecError>& errors);
  std::uint64_t pings() const { return pings_; }  // "* PING" seen (the instrument answers)
  std::uint64_t pongs() const { return pongs_; }
  // The heartbeat period the last "* PONG <ms>" gave (the agent pings every <ms> and takes
  // silence longer than twice that as a lost connection); nullopt before a PONG with a number.
  std::optional<std::int64_t> pong_timeout_ms() const { return pong_timeout_ms_; }
  std::uint64_t commands() const { return commands_; }  // other '*' lines
  const std::string& last_command() const { return last_command_; }
  std::uint64_t assets() const { return assets_; }  // multi-line values skipped
  // With config.census: the keys not configured whose values were numbers, in the order first
  // seen (the first census_limit of them: a hostile stream cannot grow it).
  static constexpr std::size_t census_limit = 256;
  const std::vector<std::string>& numeric_keys_seen() const { return numeric_keys_; }

  const ShdrConfig& config() const { return config_; }
  static std::string ping() { return "* PING\n"; }

 private:
  void decode(std::string_view line, std::uint64_t offset, std::vector<PositionFrame>& frames,
              std::vector<CodecError>& errors);
  void heartbeat(std::string_view line);
  ShdrConfig config_;
  LineSplitter splitter_;
  std::string multiline_tag_;  // inside a multi-line value until this marker comes back
  std::uint64_t pings_ = 0, pongs_ = 0, commands_ = 0, assets_ = 0;
  std::string last_command_;
  std::optional<std::int64_t> pong_timeout_ms_;
  std::optional<double> relative_origin_ms_;  // the first relative timestamp
  std::vector<std::string> numeric_keys_;
  std::set<std::string, std::less<>> numeric_key_set_;
  void count_key(std::string_view key, std::string_view value);
};

// "2024-01-01T12:00:00.123456Z" (fraction optional, Z optional) as Unix ns; nullopt if not.
std::optional<std::int64_t> parse_iso8601_utc_ns(std::string_view s);

// The tokens of an SHDR line as the agent's tokenizer makes them (see above).
std::vector<std::string> shdr_tokens(std::string_view line);

}  // namespace cal::drivers::codec
