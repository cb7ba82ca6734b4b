#pragma once
// What a command that lists runs reads, from either store: the local SQLite file (Store) or the
// central store on PostgreSQL (cal::storage::pg::open_central). One interface, two
// implementations (issue 35); so far `daq runs` reads through it, the other read commands still
// read the SQLite Store only (docs/storage.md, "Central store").
#include <cstdint>
#include <string>
#include <vector>

namespace cal::storage {

struct RunRecord;

class RunReader {
 public:
  virtual ~RunReader() = default;
  // The file, or the server's URI with its password hidden: what listings and messages name.
  virtual std::string name() const = 0;
  // Every run, by id.
  virtual std::vector<RunRecord> runs() const = 0;
  virtual std::int64_t reading_count(std::int64_t run_id) const = 0;
};

}  // namespace cal::storage
