#pragma once
// Attocube IDS3010 displacement interferometer: JSON-RPC 2.0 over TCP (port 9090), one JSON
// object per line in each direction. Source: attocube's public API repository
// github.com/attocube-systems/IDS-APIs (python/*.py and the matlab/*.m wrappers, which show the
// exact request line
//   {"jsonrpc": "2.0", "method": "com.attocube.sen.displacement.getAxesDisplacement",
//    "params": [], "id": 1, "api": 2}
// and that result[0] is the error or warning number, result[1..] the values; displacements and
// positions are in picometres). Two API generations: firmware before 1.9.1 names the
// displacement and system interfaces com.attocube.ids.*, firmware 1.9.1 and later (the
// repository's commit "API-Update for IDS-Firmware 1.9.1", July 2025) com.attocube.sen.*; the
// ECU (com.attocube.ecu.*) and the system service (com.attocube.system.*: getFirmwareVersion,
// errorNumberToString) keep their names. Details and units: docs/codecs.md.
#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "cal/drivers/codec/common.hpp"

namespace cal::drivers::codec {

// The top-level JSON objects of `text` in order ({...}, braces inside strings ignored), as
// views into it; text outside them that is not white space, and an object left open, are
// returned as pieces of their own (so that parsing them reports them). ACS.py writes requests
// unterminated, so one line of a capture may hold a request and its answer.
std::vector<std::string_view> json_objects(std::string_view text);
// One past the '}' that closes the JSON object opening at text[open] (strings respected), or
// npos when the text ends first: where an unterminated request ends (the twin's framing).
std::size_t json_object_end(std::string_view text, std::size_t open);

// The generation of the displacement and system interfaces (see above).
enum class IdsApi { ids, sen };
std::string_view to_string(IdsApi api);  // "com.attocube.ids", "com.attocube.sen"

enum class IdsMethod {
  get_axes_displacement,     // com.attocube.<gen>.displacement.getAxesDisplacement -> 3 x pm
  get_axis_displacement,     // ...displacement.getAxisDisplacement [axis] -> pm
  get_absolute_positions,    // ...displacement.getAbsolutePositions -> 3 x pm
  get_measurement_enabled,   // ...displacement.getMeasurementEnabled -> bool
  start_measurement,         // com.attocube.<gen>.system.startMeasurement
  stop_measurement,          // com.attocube.<gen>.system.stopMeasurement
  start_optics_alignment,    // com.attocube.<gen>.system.startOpticsAlignment
  stop_optics_alignment,     // com.attocube.<gen>.system.stopOpticsAlignment
  get_current_mode,          // com.attocube.<gen>.system.getCurrentMode -> string
  get_system_error,          // com.attocube.<gen>.system.getSystemError
  reset_axes,                // com.attocube.<gen>.system.resetAxes
  ecu_enable,                // com.attocube.ecu.enable
  ecu_get_enabled,           // com.attocube.ecu.getEnabled -> bool
  ecu_get_connected,         // com.attocube.ecu.getConnected -> bool
  ecu_get_temperature,       // com.attocube.ecu.getTemperatureInDegrees -> degC
  ecu_get_pressure,          // com.attocube.ecu.getPressureInHPa -> hPa
  ecu_get_humidity,          // com.attocube.ecu.getHumidityInPercent -> %RH
  ecu_get_refractive_index,  // com.attocube.ecu.getRefractiveIndex -> n
  get_firmware_version,      // com.attocube.system.getFirmwareVersion -> string
  error_number_to_string,    // com.attocube.system.errorNumberToString [language, n] -> string
};
// The full JSON-RPC method name, e.g. "com.attocube.ecu.getPressureInHPa" (the generation
// matters only for the displacement and system interfaces).
std::string method_name(IdsMethod method, IdsApi api = IdsApi::ids);
// True for the methods whose result[0] is a warning number (the displacement getters: the
// attocube wrappers call it warningNo there, errNo elsewhere).
bool returns_warning(IdsMethod method);

using IdsParam = std::variant<std::int64_t, double, bool>;

// One decoded response, matched by id to the request that asked for it.
struct IdsResponse {
  std::int64_t id = 0;
  IdsMethod method = IdsMethod::get_axes_displacement;
  IdsApi api = IdsApi::ids;          // the generation the request was made in
  std::vector<std::int64_t> params;  // the request's integer params (errorNumberToString's)
  bool rpc_error = false;            // a JSON-RPC error object (e.g. -32601 unknown method)
  // result[0]: 0 = ok; otherwise the device's error/warning number (errorNumberToString on the
  // device turns it into text). For a JSON-RPC "error" object, its code.
  std::int64_t error_code = 0;
  std::string error_message;  // the JSON-RPC error message, if any
  // getAxesDisplacement / getAbsolutePositions: axes 0..2; getAxisDisplacement: axis 0 slot.
  std::array<std::optional<double>, 3> displacement_m{};
  std::optional<double> temperature_degc;
  std::optional<double> pressure_pa;
  std::optional<double> humidity_pct_rh;
  std::optional<double> refractive_index;
  std::optional<bool> flag;  // getMeasurementEnabled, ecu.getConnected, ecu.getEnabled
  std::string mode;          // getCurrentMode, e.g. "measurement running"
  std::string text;          // every string result (mode, firmware version, error text)
};

// Plausibility limits; a value outside is an out_of_range error and is left out of the frame.
// The displacement bound is a sanity bound (the IDS3010 working range is metres, not tens of
// metres); the ECU bounds are those of indoor air around a machine tool.
struct IdsLimits {
  double max_abs_displacement_m = 10.0;
  double min_temperature_degc = -20.0, max_temperature_degc = 60.0;
  double min_pressure_pa = 50e3, max_pressure_pa = 120e3;
  double min_humidity_pct_rh = 0.0, max_humidity_pct_rh = 100.0;
  double min_refractive_index = 1.0, max_refractive_index = 1.001;
};

class IdsCodec : public CodecBase<IdsCodec, IdsResponse> {
 public:
  // Requests still waiting for an answer beyond this are forgotten (oldest first), so a device
  // that never answers cannot make the codec grow without bound.
  static constexpr std::size_t max_pending = 256;

  explicit IdsCodec(IdsLimits limits = {},
                    std::size_t max_line_bytes = LineSplitter::default_max_line_bytes);

  // The request line (with its '\n') for `method` in the current API generation, with the next
  // id (1, 2, 3, ...); the id is remembered so that the response can be matched. Throws
  // cal::InputError if the number of params does not fit the method (e.g. getAxisDisplacement
  // needs the axis 0..2).
  std::string encode(IdsMethod method, std::span<const IdsParam> params = {});
  void set_api(IdsApi api) { api_ = api; }
  IdsApi api() const { return api_; }
  std::int64_t last_id() const { return next_id_ - 1; }
  // Replay: learns the requests of a recorded session from the bytes that were sent (request
  // lines as encode() writes them, of either generation), so that their answers match.
  // Unknown lines are ignored. The lines encode() writes are recognised in one pass (their
  // method compared with a table built once), others through the JSON parser.
  void note_requests(std::span<const std::byte> bytes);
  std::size_t pending() const { return pending_.size(); }

  void do_feed(std::span<const std::byte> bytes, std::vector<IdsResponse>& frames,
               std::vector<CodecError>& errors);

 private:
  class ResultView;  // result[] as the one-pass reader or the JSON parser gives it (codec.cpp)

  void note_request(std::string_view line);
  void learn(std::int64_t id, std::string_view method, std::vector<std::int64_t> params);
  void decode_line(std::string_view line, std::uint64_t offset, std::vector<IdsResponse>& frames,
                   std::vector<CodecError>& errors);
  // The pending request answered by `id`, forgotten; nullopt (and an error) if there is none.
  std::optional<IdsResponse> take_pending(std::int64_t id, std::uint64_t offset,
                                          std::vector<CodecError>& errors);
  void report_no_result(std::int64_t id, std::uint64_t offset, std::vector<CodecError>& errors);
  void decode_result(IdsResponse r, const ResultView& res, std::uint64_t offset,
                     std::vector<IdsResponse>& frames, std::vector<CodecError>& errors);

  IdsLimits limits_;
  LineSplitter splitter_;
  LineSplitter sent_splitter_;
  struct Pending {
    IdsMethod method;
    IdsApi api;
    std::vector<std::int64_t> params;
  };
  void remember(std::int64_t id, Pending p);

  std::int64_t next_id_ = 1;
  IdsApi api_ = IdsApi::ids;
  std::map<std::int64_t, Pending> pending_;
  std::map<std::int64_t, Pending>::node_type spare_;  // an answered request's node, for reuse
};

}  // namespace cal::drivers::codec
