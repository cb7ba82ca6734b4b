#pragma once
// The run store: one SQLite file (one per site by default), WAL mode, a versioned schema
// with migrations. Raw readings are kept uncompensated, in chunks (a BLOB of timestamps and
// values per device/channel/quantity), so a run can be re-compensated and re-analysed later
// and ingest keeps up with a 10 kHz interferometer many times over. Nothing is lost on a
// crash: every committed batch survives a kill -9 or a power loss (synchronous=FULL), and a
// run that never finished is shown as incomplete when the store is next opened.
//
// sqlite3.h stays out of this header.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace cal::storage {

// Every storage failure: the message names the database file and what failed (SQLite's own
// text, e.g. "database or disk is full").
class StoreError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// 1: the first schema. 2: results carry their provenance; missed stops; the runs' time origin.
// 3: reading chunks carry an encoding, a sequence number in their run and a checksum
// (docs/storage.md). 4: ballbar calibrations (issue 18). 5 (issue 26): the instruments' origin
// (real, simulated, replay), the compensation tables written with their predicted residual, and
// the quality of a run's stops (suspect stops, the run's verdict). 6 (issue 29): the operator's
// actions during a run (OperatorAction). 7 (issue 35): every run has a stable identity, a UUID
// (RunRecord::uuid), by which the central store (daq sync) knows it. 8 (issue 35): every machine
// has one too (MachineRecord::uuid): two sites' machines of the same name stay apart centrally.
// 9 (issue 35): sign-off: a result's approval (Approval: who, when), which a report needs to be
// issued as a certificate (central schema 6 has its own, with the reviewers' role). 10 (issue
// 35): the central server's approvals of the results brought by daq sync --from, read-only here.
// 11 (issue 35): machine models kept in the store (ModelRecord), with their provenance and a
// stable UUID, which daq sync sends and brings like runs.
inline constexpr int schema_version = 11;

// A new random (version 4) UUID in its canonical lower-case text form.
std::string new_uuid();
// Whether `text` is a UUID in canonical form (8-4-4-4-12 lower-case hex digits).
bool is_uuid(std::string_view text);

enum class RunStatus { running, complete, incomplete, aborted };
std::string_view to_string(RunStatus s);

struct MachineRecord {
  std::int64_t id = 0;
  std::string name;
  std::string description;
  std::string config_json = "{}";
  // Its stable identity (schema 8): given at add_machine (a new one when empty); the central
  // store tells machines apart by it. "" only for an older database opened read-only.
  std::string uuid;
};

struct RunRecord {
  std::int64_t id = 0;
  std::int64_t machine_id = 0;
  std::string campaign;              // free text grouping runs, e.g. "2026-11 annual"
  std::string kind;                  // "linear", "circle", "straightness", ...
  std::string axis;                  // "X", "XY", ...
  std::string settings_json = "{}";  // test set-up: targets, cycle, feed, compensation, ...
  std::string capture_path;          // the wire-level capture of the run, if one was recorded
  std::string software_version;
  std::int64_t started_unix_ms = 0;
  std::optional<std::int64_t> ended_unix_ms;
  RunStatus status = RunStatus::running;
  std::string note;  // why a run was aborted, and the like
  // The run's time origin: the session clock (the readings' time_ns) at a known UTC instant,
  // taken when the first reading arrived. Unset for runs stored before schema 2 and imports.
  std::optional<std::int64_t> origin_session_ns, origin_unix_ns;
  // The run's stable identity (schema 7): given at begin_run (a new one when empty), never
  // changed; the central store knows the run by it. "" only for an older database opened
  // read-only.
  std::string uuid;
};

struct InstrumentRecord {
  std::int64_t run_id = 0;
  int device = 0;         // the device number used in the run's readings
  std::string driver;     // "ids3010", "ptu300", ...
  std::string transport;  // "tcp 192.168.1.5:9090", "serial /dev/ttyUSB0 4800 7E1"
  std::string settings_json = "{}";
  // Where the readings came from: "real" (a device), "simulated" (a twin of the simulated
  // shop), "replay" (a capture pushed through the driver again), "imported" (a file of another
  // tool), "" (not recorded: stored before schema 5). origin_detail says which capture, which
  // simulated shop, which file.
  std::string origin;
  std::string origin_detail;
};
// A compensation table written for the controller (daq compensate, daq model compensate), kept
// so that the next measurement of the axis can be compared with what it was predicted to leave.
struct CompensationRecord {
  std::int64_t id = 0;  // set when stored
  std::int64_t machine_id = 0;
  std::int64_t source_run_id = 0;  // 0: from a model or a file
  std::string source;              // e.g. "run 7", "model yfxz.json"
  std::string axis;
  std::string format;
  std::int64_t created_unix_ms = 0;  // 0: now
  std::string json;                  // caldaq.compensation.v1 (docs/compensation-tables.md)
};

// A machine model kept in a store (schema 11; central schema 10): the model file's JSON
// (caldaq.model.v1/v2, docs/model-file.md) as daq model build wrote it, with where it came from.
// Never changed once stored (a model built again is another one); known in every store by its
// UUID, so sending it twice stores it once.
struct ModelRecord {
  std::int64_t id = 0;  // the store's number (set when stored; the central store numbers its own)
  std::string uuid;     // its stable identity (a new one when stored without)
  std::int64_t machine_id = 0;  // the store's machine it models
  std::string name;             // the model's name (its "name")
  std::string json;             // the model file's text
  // caldaq.model-provenance.v1 (docs/storage.md, "Models"): how it was made and stored: the
  // command, the runs it was built from (their UUIDs, ids, kinds, start times and versions of
  // their stops), the file it was read from.
  std::string provenance_json = "{}";
  std::string stored_by;            // who stored it (the OS account where it was stored)
  std::string stored_from;          // the host
  std::int64_t stored_unix_ms = 0;  // when (0 when stored: now)
};

// One raw reading (the storage's own POD, so storage does not depend on drivers).
struct RawReading {
  std::int64_t time_ns = 0;
  std::uint16_t device = 0;
  std::uint8_t channel = 0;
  std::uint8_t quantity = 0;  // cal::drivers::Quantity
  std::uint8_t status = 0;    // cal::drivers::ReadingStatus
  double value = 0.0;
};

struct CapturedTarget {
  std::int64_t run_id = 0;
  int target_index = 0;  // 0-based, as in the plan
  int run_number = 0;    // 1-based ISO 230-2 run j
  char direction = '+';  // '+' or '-'
  double nominal_mm = 0.0;
  std::int64_t time_ns = 0;
  double raw_m = 0.0;         // the laser reading used (mean over the capture window)
  double deviation_um = 0.0;  // compensated actual minus nominal, at 20 degC
  double refractive_index = 1.0;
  double material_temperature_degc = 20.0;
};

// A run's stops checked against the run's own repeatability (cal::quality::assess;
// docs/iso230-2.md, "Suspect stops"): the verdict, its summary in words and the suspect stops.
struct StopMark {
  int run_number = 0;
  char direction = '+';
  int target_index = 0;
  std::string reason;
};
struct RunQuality {
  std::string state;    // "ok", "suspect" or "not checked"
  std::string summary;  // the verdict in words, with the rule's numbers
  std::vector<StopMark> suspects;
};

struct ResultRecord {
  std::int64_t run_id = 0;
  std::string standard;  // "ISO 230-2:2014", "VDI/DGQ 3441", "ISO 230-4"
  std::string json;      // the full result document (caldaq.*.v1 schema)
  std::int64_t created_unix_ms = 0;
  // How the result was obtained (caldaq.provenance.v1, docs/storage.md): acquired, re-analysed,
  // re-compensated (of which result, what changed) or replayed (of which run); the
  // coefficients and sensor offsets used; the software; when.
  std::string provenance_json = "{}";
  std::int64_t id = 0;                        // set when read back
  std::optional<std::int64_t> superseded_by;  // unset: the current result
  bool current() const { return !superseded_by.has_value(); }
};

// Which earlier results of the run a new result makes out of date (they stay stored, marked
// superseded by the new one).
enum class Supersede {
  none,           // e.g. an evaluation by another standard shown but kept apart
  same_standard,  // a new evaluation by the same standard (the default)
  all,            // the captured data changed (re-compensation): every earlier result
};

// A planned stop of a linear run that was never captured.
struct MissedStop {
  std::int64_t run_id = 0;
  int run_number = 0;    // 1-based ISO 230-2 run j
  char direction = '+';  // '+' or '-'
  int target_index = 0;  // 0-based, as in the plan
  double nominal_mm = 0.0;
};

// What the operator did during a run, as it happened: "capture" (a stop captured by hand),
// "skip" (a target given up), "retry" (the last stop measured again: its value discarded),
// "pause", "resume". `stop` names the stop acted on (a stop of the plan; run_id as the action's).
struct OperatorAction {
  std::int64_t run_id = 0;
  std::int64_t time_unix_ms = 0;  // 0 when stored: now
  std::string action;
  std::string source;         // where it came from: "web page", "keyboard (daq run)", ...
  std::string operator_name;  // the configuration's operator, "" when not stated
  std::optional<MissedStop> stop;
  std::string detail;  // what happened, in words (the value captured, the value discarded)
};

// A ballbar's calibration against a calibrator of known length (a Zerodur jig, a known ring):
// the bar (with its extensions) in the calibrator reads `reading_mm`, so it reads 0 at
// zero_length_mm = calibrator_length_mm - reading_mm, its calibrated length. Used for the
// absolute radius of later tests of that bar at that nominal length (docs/circle.md).
struct BarCalibration {
  std::int64_t id = 0;                // set when stored
  std::string bar;                    // the bar's identity (serial number)
  double nominal_mm = 0.0;            // the nominal length of bar + extensions (the test radius)
  std::string extensions;             // which extensions, as the operator names them ("" none)
  std::string calibrator;             // the calibrator's identity
  double calibrator_length_mm = 0.0;  // its certified length
  double reading_mm = 0.0;            // the bar's reading in the calibrator
  double zero_length_mm = 0.0;        // calibrator_length_mm - reading_mm
  std::optional<double> temperature_degc;  // as recorded (not used to correct: docs/circle.md)
  std::int64_t calibrated_unix_ms = 0;     // when
  std::string note;
};

struct StoreOptions {
  bool full_sync = true;  // synchronous=FULL: a committed batch survives a power loss
  // A cap on the file size in pages (0: none). SQLite then fails a write exactly as on a full
  // disk ("database or disk is full"), which is how the tests exercise that path.
  std::int64_t max_pages = 0;
  // Open for reading only: the file must exist and be a caldaq database; nothing is written
  // at open or after (no migration, no marking of interrupted runs, no journal mode change),
  // so it works on a full disk and on a read-only medium. An older schema is read as it is.
  // Every writing method then throws StoreError.
  bool read_only = false;
};

class ReadingStream;

// One version of a run's stops in the central store (issue 35): the same run changed in two
// places (re-compensated on two laptops) is kept as versions, never overwritten.
struct RunVersion {
  int version = 0;         // 1, 2, ... in the order the server got them
  std::string status;      // the run's status when this version was sent
  std::string sent_by;     // the user who sent it
  std::string sent_from;   // the host it came from
  std::string sent_store;  // the store (path) it came from
  std::int64_t sent_unix_ms = 0;
  std::int64_t stops = 0;  // captured stops in this version
  bool current = false;    // the version the read commands read (the newest sent)
};

// A reviewer's sign-off of one result of a run (issue 35; docs/storage.md, "Sign-off"): a report
// is issued as a certificate only when the result it shows is approved. It names the exact
// result: a re-analysis or re-compensation since makes a new result, which is not approved.
struct Approval {
  std::int64_t result_id = 0;  // the result approved (its id in the store read)
  // The central store: the result's content fingerprint and the run's version of its stops when
  // it was approved ("" and 0 in a local store, where the result id is the exact version).
  std::string result_fingerprint;
  int run_version = 0;
  std::string approved_by;  // the reviewer: the server's login role; locally the OS account
  std::int64_t approved_unix_ms = 0;
  // Made on the central server: that server (its URI, password hidden), read there or brought
  // from there by daq sync --from (read-only in the local store); "" for a local approval.
  std::string central_server;
};

// The series of a run (one per device, channel and quantity) with their counts and time spans,
// from the chunks' rows alone (no reading is decoded).
struct SeriesInfo {
  std::uint16_t device = 0;
  std::uint8_t channel = 0, quantity = 0;
  std::int64_t count = 0, first_ns = 0, last_ns = 0;
};

// What every read command reads, from either store (issue 35): the local SQLite file (Store) or
// the central store on PostgreSQL (cal::storage::pg::open_central). One interface, two
// implementations; `daq runs`, `show`, `export`, `report`, `analyse RUN`, `model build` and
// `ballbar history` read through it. Ids are those of the store read (the central store numbers
// runs in the order it first saw them; a result keeps the id it had where it was made).
class RunReader {
 public:
  virtual ~RunReader() = default;
  // The file, or the server's URI with its password hidden: what listings and messages name.
  virtual std::string name() const = 0;
  virtual std::optional<MachineRecord> machine_by_name(std::string_view name) const = 0;
  virtual std::optional<MachineRecord> machine(std::int64_t id) const = 0;
  // Every run, by id.
  virtual std::vector<RunRecord> runs() const = 0;
  virtual std::optional<RunRecord> run(std::int64_t run_id) const = 0;
  virtual std::vector<InstrumentRecord> instruments(std::int64_t run_id) const = 0;
  virtual std::int64_t reading_count(std::int64_t run_id) const = 0;
  // A run's readings in order, a batch at a time, in bounded memory (see ReadingStream). Order:
  // time, then device, channel, quantity; readings of one series with equal times in the order
  // they were stored. `quantities` (cal::drivers::Quantity values; empty: all) selects whole
  // series. Every chunk's checksum is verified as it is read; a damaged chunk throws StoreError
  // naming the run and the chunk. The stream must not outlive its reader.
  virtual ReadingStream stream_readings(std::int64_t run_id,
                                        std::span<const std::uint8_t> quantities = {}) const = 0;
  // All readings of a run (or of these quantities) at once, in the same order: for runs known
  // to be short. The memory is the run's size; prefer stream_readings.
  std::vector<RawReading> readings(std::int64_t run_id) const;
  std::vector<RawReading> readings(std::int64_t run_id,
                                   std::span<const std::uint8_t> quantities) const;
  virtual std::vector<SeriesInfo> series(std::int64_t run_id) const = 0;
  virtual std::vector<CapturedTarget> targets(std::int64_t run_id) const = 0;
  // Every result of the run, oldest first, with its provenance and whether it is current.
  virtual std::vector<ResultRecord> results(std::int64_t run_id) const = 0;
  // nullopt: never stored (see Store::quality).
  virtual std::optional<RunQuality> quality(std::int64_t run_id) const = 0;
  virtual std::vector<MissedStop> missed_stops(std::int64_t run_id) const = 0;
  virtual std::vector<OperatorAction> operator_actions(std::int64_t run_id) const = 0;
  // Ballbar calibrations: every one, or those of one bar, oldest first; the newest of the bar at
  // this nominal length (within 1 um) made at or before the time.
  virtual std::vector<BarCalibration> bar_calibrations(std::string_view bar = {}) const = 0;
  virtual std::optional<BarCalibration> bar_calibration(std::string_view bar, double nominal_mm,
                                                        std::int64_t at_unix_ms) const = 0;
  // Compensation tables written, of a machine's axis, oldest first (machine_id 0 / axis "": any).
  virtual std::vector<CompensationRecord> compensations(std::int64_t machine_id = 0,
                                                        std::string_view axis = {}) const = 0;
  // The versions of a run's stops, oldest first (empty: the store keeps one, as a local one).
  virtual std::vector<RunVersion> versions(std::int64_t /*run_id*/) const { return {}; }
  // The approvals of the run's results, oldest first.
  virtual std::vector<Approval> approvals(std::int64_t run_id) const = 0;
  // The models kept (schema 11), by id (machine_id 0: every machine's); one by the store's
  // number or by its UUID (nullopt: none).
  virtual std::vector<ModelRecord> models(std::int64_t machine_id = 0) const = 0;
  virtual std::optional<ModelRecord> model(std::int64_t id) const = 0;
  virtual std::optional<ModelRecord> model_by_uuid(std::string_view uuid) const = 0;
};

// A reading chunk as a store hands it to a ReadingStream: its row and its bytes.
struct SourceChunk {
  std::int64_t order = 0;  // the order written among chunks of equal first times (SQLite's row)
  std::optional<std::int64_t> seq;  // its number in the run (unset: written before schema 3)
  std::int64_t device = 0, channel = 0, quantity = 0;
  std::int64_t first_ns = 0, last_ns = 0, count = 0, encoding = 0;
  std::optional<std::uint32_t> crc;  // the stored checksum (unset: none, before schema 3)
  std::vector<unsigned char> data;
};

// Where a ReadingStream gets its chunks from: one implementation per store.
class ChunkSource {
 public:
  virtual ~ChunkSource() = default;
  // The next chunk of the run (with the stream's quantities) in the order of (first_ns,
  // order); false when none are left.
  virtual bool next(SourceChunk& out) = 0;
  // The numbered chunks of the run (with the stream's quantities) by the store's other index:
  // their count and largest seq (-1: none). nullopt: the store does not number chunks.
  struct Numbered {
    std::int64_t count = 0, max_seq = -1;
  };
  virtual std::optional<Numbered> numbered() = 0;
};

// A batch of readings grouped into its chunks (one per device/channel/quantity, in order of
// first appearance) and encoded: what Store::append_readings stores, prepared apart so that a
// writer can encode one batch while the store commits the previous one.
struct PreparedBatch {
  struct Chunk {
    std::uint32_t series = 0;  // device << 16 | channel << 8 | quantity
    std::int64_t first_ns = 0, last_ns = 0, count = 0;
    std::vector<unsigned char> blob;  // encoding 2 (chunk.hpp)
  };
  std::vector<Chunk> chunks;  // the first `used` are this batch's (the rest reused storage)
  std::size_t used = 0;
  std::size_t reading_count = 0;
  // Groups and encodes `readings` (replacing what was held); pure, any thread.
  void prepare(std::span<const RawReading> readings);
};

class Store : public RunReader {
 public:
  // Opens or creates the database, migrates it to schema_version, and marks runs left
  // `running` by a crashed session as `incomplete`. Throws StoreError (file named) when the
  // file is not a database, is another program's SQLite database, is from a newer version,
  // or cannot be written.
  //
  // With options.read_only: opens an existing caldaq database without writing anything (see
  // StoreOptions::read_only); a missing file is an error naming the path. Runs whose writing
  // process is gone are shown `incomplete` without being marked so in the file.
  explicit Store(const std::filesystem::path& path, StoreOptions options = {});
  ~Store();
  Store(Store&&) noexcept;
  Store& operator=(Store&&) noexcept;

  const std::filesystem::path& path() const;
  std::string name() const override;  // the path
  int version() const;                // the schema version found on disk after migration
  bool read_only() const;

  std::int64_t add_machine(const MachineRecord& m);
  std::optional<MachineRecord> machine_by_name(std::string_view name) const override;
  std::optional<MachineRecord> machine(std::int64_t id) const override;
  std::optional<MachineRecord> machine_by_uuid(std::string_view uuid) const;

  std::int64_t begin_run(const RunRecord& r);  // returns the new run id
  void add_instrument(const InstrumentRecord& i);
  void finish_run(std::int64_t run_id, RunStatus status, std::string_view note = {});
  void set_capture_path(std::int64_t run_id, std::string_view path);
  std::vector<RunRecord> runs() const override;
  std::optional<RunRecord> run(std::int64_t run_id) const override;
  std::optional<RunRecord> run_by_uuid(std::string_view uuid) const;
  std::vector<InstrumentRecord> instruments(std::int64_t run_id) const override;

  // Appends readings in one transaction: one chunk per device/channel/quantity, each with its
  // sequence number in the run and its checksum (chunk.hpp).
  void append_readings(std::int64_t run_id, std::span<const RawReading> readings);
  // The same for a batch prepared beforehand (append_readings = prepare + this): the same rows.
  void append_prepared(std::int64_t run_id, const PreparedBatch& batch);

  // A run's readings in order, a batch at a time, in bounded memory (see ReadingStream): the
  // way to read a long run. Order: time, then device, channel, quantity; readings of one
  // series with equal times in the order they were stored. `quantities` (cal::drivers::Quantity
  // values; empty: all) selects whole series, e.g. the environment of a long laser run.
  // Every chunk's checksum is verified as it is read; a damaged chunk throws StoreError naming
  // the run and the chunk. The stream uses this store's connection: it must not outlive it.
  ReadingStream stream_readings(std::int64_t run_id,
                                std::span<const std::uint8_t> quantities = {}) const override;
  using RunReader::readings;  // all at once (RunReader::readings)
  std::int64_t reading_count(std::int64_t run_id) const override;
  // The series of a run from the chunks' rows alone (no reading is decoded): what a reader
  // needs to know before it streams, e.g. how far to thin a series for a plot.
  using Series = SeriesInfo;
  std::vector<Series> series(std::int64_t run_id) const override;

  // A reading chunk as stored, its BLOB not decoded: what daq sync copies to the central store.
  struct StoredChunk {
    std::int64_t seq = 0;  // its place in the run (0, 1, 2, ...)
    std::int64_t device = 0, channel = 0, quantity = 0;
    std::int64_t first_ns = 0, last_ns = 0, count = 0;
    std::int64_t encoding = 0;
    std::uint32_t crc = 0;  // chunk::checksum of the row (with the run's local id) and BLOB
    // false for a chunk written before schema 3: it was unnumbered and had no checksum; seq is
    // then its place in the order written and crc is computed now, at reading.
    bool stored_checksum = true;
    std::vector<unsigned char> data;
  };
  // The run's chunks in the order written, from the `first`-th (0-based), at most `max_chunks`.
  // Every stored checksum is verified: a damaged chunk throws StoreError naming it.
  std::vector<StoredChunk> stored_chunks(std::int64_t run_id, std::int64_t first,
                                         std::size_t max_chunks) const;
  std::int64_t chunk_count(std::int64_t run_id) const;

  void add_targets(std::span<const CapturedTarget> targets);
  std::vector<CapturedTarget> targets(std::int64_t run_id) const override;
  // Replaces the targets of a run (re-compensation keeps the raw values, changes deviations).
  void replace_targets(std::int64_t run_id, std::span<const CapturedTarget> targets);

  // Stores a result (returns its id) and marks the earlier ones it makes out of date.
  std::int64_t add_result(const ResultRecord& r, Supersede s = Supersede::same_standard);
  // Every result of the run, oldest first, with its provenance and whether it is current.
  std::vector<ResultRecord> results(std::int64_t run_id) const override;
  // Re-compensation in one transaction: the new deviations of the stops and the result made
  // from them, which supersedes every earlier result (a crash leaves the old pair intact).
  std::int64_t replace_targets(std::int64_t run_id, std::span<const CapturedTarget> targets,
                               const ResultRecord& result);

  // The planned stops a linear run never captured (replaces what was stored).
  void set_missed_stops(std::int64_t run_id, std::span<const MissedStop> stops);
  // The run's stop quality, replacing what was stored; throws StoreError for an unknown state.
  void set_quality(std::int64_t run_id, const RunQuality& q);
  // nullopt: never stored (a run stored before schema 5, an import; an older database opened
  // read-only): assess it from its stops (daq's run_quality()).
  std::optional<RunQuality> quality(std::int64_t run_id) const override;
  std::vector<MissedStop> missed_stops(std::int64_t run_id) const override;
  // The operator's actions of a run (OperatorAction), stored one by one as they happen, and read
  // back in that order. An unknown action is refused by the schema (StoreError).
  void add_operator_action(const OperatorAction& a);
  std::vector<OperatorAction> operator_actions(std::int64_t run_id) const override;
  // The session clock reading at a UTC instant (ns since the Unix epoch), see RunRecord.
  void set_time_origin(std::int64_t run_id, std::int64_t session_ns, std::int64_t unix_ns);

  // Ballbar calibrations (returns the new id). Throws StoreError for a non-finite or
  // non-positive length, or an empty bar identity.
  std::int64_t add_bar_calibration(const BarCalibration& c);
  // Every calibration, or those of one bar, oldest first.
  std::vector<BarCalibration> bar_calibrations(std::string_view bar = {}) const override;
  // The newest calibration of the bar at this nominal length (within 1 um) made at or before
  // the time, or nullopt.
  std::optional<BarCalibration> bar_calibration(std::string_view bar, double nominal_mm,
                                                std::int64_t at_unix_ms) const override;

  // Compensation tables written (returns the new id), and those of a machine's axis, oldest
  // first (machine_id 0 / axis "": any).
  std::int64_t add_compensation(const CompensationRecord& c);
  std::vector<CompensationRecord> compensations(std::int64_t machine_id = 0,
                                                std::string_view axis = {}) const override;

  // Keeps a model (returns its id): its UUID kept when given (a model brought by daq sync
  // --from), else a new one. Throws StoreError for a machine not here, a UUID that is not one or
  // is here already, an empty model text.
  std::int64_t add_model(const ModelRecord& m);
  std::vector<ModelRecord> models(std::int64_t machine_id = 0) const override;
  std::optional<ModelRecord> model(std::int64_t id) const override;
  std::optional<ModelRecord> model_by_uuid(std::string_view uuid) const override;

  // Sign-off (schema 9): records that `approved_by` approved result `result_id` of the run, now.
  // Refused (StoreError saying why) for a result of another run, one superseded since (a
  // re-analysis or re-compensation: approve the current one), or one approved already.
  Approval approve(std::int64_t run_id, std::int64_t result_id, std::string_view approved_by);
  // The run's approvals: the central server's (brought by daq sync --from) first, then the local.
  std::vector<Approval> approvals(std::int64_t run_id) const override;
  // daq sync --from: the central server's approval of a result here (a.result_id: the local id;
  // a.central_server set). False, and nothing stored, when that result has one already (the
  // server's approvals are made once and never changed).
  bool add_central_approval(const Approval& a);
  // daq sync --from: the operator's actions of a run brought from the central store, as the server
  // has them now (replacing those here). False, and nothing changed, for a run acquired here.
  bool replace_imported_operator_actions(std::int64_t run_id,
                                         std::span<const OperatorAction> actions);

  // A run brought by daq sync --from while it was still running there (acquired elsewhere): its
  // status, end and note as the server has them now (r.id: the local run). False, and nothing
  // changed, for a run acquired here.
  bool update_imported_run(const RunRecord& r);

  // What daq sync --from brings from the central store (issue 35). f runs in one transaction:
  // every write it makes (by the methods here) is committed together, or none on a throw.
  void in_transaction(const std::function<void()>& f);
  // A run as another store recorded it, its UUID, status, times and origin kept (begin_run
  // starts a new one); returns its new local id. A UUID already here is a StoreError.
  std::int64_t import_run(const RunRecord& r);
  // Another store's reading chunks of the run, appended with their numbers, which must continue
  // the run's (0, 1, 2, ...). Each one's checksum is computed for this store's run id: the
  // caller has checked the bytes against the checksum they came with.
  void add_stored_chunks(std::int64_t run_id, std::span<const StoredChunk> chunks);
  // Marks a result superseded by another of the same run (as the store it came from had it).
  void set_superseded(std::int64_t result_id, std::int64_t by_result_id);

  struct Impl;  // implementation, shared with ReadingStream (store.cpp)

 private:
  std::unique_ptr<Impl> impl_;
};

// A run's readings in order (see Store::stream_readings). The chunks are merged in the order
// of their first times, so only the chunks that overlap the current time are held: for a run
// written by the batch writer, one chunk per series (16384 readings each at most), whatever
// the run's length.
class ReadingStream {
 public:
  ~ReadingStream();
  ReadingStream(ReadingStream&&) noexcept;
  ReadingStream& operator=(ReadingStream&&) noexcept;

  // Replaces `out` with the next readings, at most max_readings (> 0); false when none are
  // left (out is then empty). Throws StoreError when a chunk is damaged or missing.
  bool next(std::vector<RawReading>& out, std::size_t max_readings = 65536);
  std::uint64_t chunks_read() const;

  // The stream of a run's chunks from `source`. `where` names the store and `run_id` the run in
  // messages; the checksums cover `checksum_run_id`, the run's id in the store that wrote the
  // chunks (the central store keeps the laptop's id of a run beside its own). `whole_run`: the
  // source gives every series of the run (no quantity filter), so the chunks' numbers must be
  // 0 .. n - 1.
  static ReadingStream of(std::unique_ptr<ChunkSource> source, std::string where,
                          std::int64_t run_id, std::int64_t checksum_run_id, bool whole_run);

 private:
  struct Impl;
  explicit ReadingStream(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace cal::storage
