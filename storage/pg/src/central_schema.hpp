#pragma once
// Private to storage/pg: the central schema's migrations and the connection's error handling.
#include <fmt/format.h>

#include <memory>
#include <pqxx/pqxx>
#include <string>
#include <string_view>

#include "cal/storage/store.hpp"

namespace cal::storage::pg {

// Creates or migrates the schema `caldaq` on this connection, in one transaction under an
// advisory lock (two syncs starting at once migrate it once); returns the version.
int migrate_schema(pqxx::connection& conn, std::string_view shown_url);

// What a reader (that never creates or migrates anything) checks first: a caldaq central store of
// exactly this daq's version is there. Throws StoreError naming the server and what is wrong.
void check_reader_schema(pqxx::connection& conn, std::string_view shown_url);

// A result's identity on the server (schema 3): md5 of its standard, creation time, document and
// provenance, computed by the server as the migration computed it for the rows it had.
std::string result_fingerprint(pqxx::transaction_base& t, const ResultRecord& r);

// The columns of a reading chunk's row that read_chunk() reads, in its order.
inline constexpr const char* kChunkColumns =
    "seq, device, channel, quantity, first_ns, last_ns, count, encoding, crc, data";

// A chunk's row (kChunkColumns) into a record with those members (SourceChunk for the readers,
// Store::StoredChunk for daq sync --from); crc is the server's, not checked here.
template <class Chunk>
void read_chunk(const pqxx::row& row, Chunk& c) {
  c.seq = row[0].as<std::int64_t>();
  c.device = row[1].as<std::int64_t>();
  c.channel = row[2].as<std::int64_t>();
  c.quantity = row[3].as<std::int64_t>();
  c.first_ns = row[4].as<std::int64_t>();
  c.last_ns = row[5].as<std::int64_t>();
  c.count = row[6].as<std::int64_t>();
  c.encoding = row[7].as<std::int64_t>();
  c.crc = static_cast<std::uint32_t>(row[8].as<std::int64_t>());
  const pqxx::binarystring data(row[9]);
  c.data.assign(data.data(), data.data() + data.size());
}

// libpq's text on one line, as every daq error: it spans lines ("...failed: Connection
// refused\n\tIs the server running...?\n"; a server's "ERROR:  permission denied ...\n").
inline std::string one_line(std::string_view text) {
  std::string out;
  for (const char c : text) {
    if (c != '\n' && c != '\t')
      out += c;
    else if (!out.empty() && out.back() != ' ')
      out += ' ';
  }
  while (!out.empty() && out.back() == ' ') out.pop_back();
  return out;
}

// The server's SQLSTATE of a refusal. libpqxx 6.4 (Debian 12's 6.4.5) throws
// pqxx::insufficient_privilege for SQLSTATE 42501 without passing the code on, so its sqlstate()
// is empty (src/result.cxx, result::ThrowSQLError: `throw insufficient_privilege{Err, Query};`,
// where every other class gets `code`; fixed upstream by libpqxx PR #1077, December 2025, in 8.0):
// the exception's type says it then.
inline std::string sqlstate(const pqxx::sql_error& e) {
  if (!e.sqlstate().empty()) return e.sqlstate();
  if (dynamic_cast<const pqxx::insufficient_privilege*>(&e) != nullptr) return "42501";
  return {};
}

// Runs f, turning libpqxx's exceptions into StoreError naming the server and what was done.
template <class F>
auto guarded(std::string_view shown_url, std::string_view what, F&& f) {
  try {
    return f();
  } catch (const StoreError&) {
    throw;
  } catch (const pqxx::sql_error& e) {
    throw StoreError(
        fmt::format("{}: {}: {} (SQLSTATE {})", shown_url, what, one_line(e.what()), sqlstate(e)));
  } catch (const std::exception& e) {
    // broken_connection and the like.
    throw StoreError(fmt::format("{}: {}: {}", shown_url, what, one_line(e.what())));
  }
}

// A connection to the server at url (shown as shown_url in errors).
inline std::unique_ptr<pqxx::connection> connect(std::string_view shown_url, std::string_view url) {
  return guarded(shown_url, "connect",
                 [&] { return std::make_unique<pqxx::connection>(std::string(url)); });
}

}  // namespace cal::storage::pg
