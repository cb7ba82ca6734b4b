#pragma once
// Private to storage/pg: the central schema's migrations and the connection's error handling.
#include <fmt/format.h>

#include <pqxx/pqxx>
#include <string>
#include <string_view>

#include "cal/storage/store.hpp"

namespace cal::storage::pg {

// Creates or migrates the schema `caldaq` on this connection, in one transaction under an
// advisory lock (two syncs starting at once migrate it once); returns the version.
int migrate_schema(pqxx::connection& conn, std::string_view shown_url);

// Runs f, turning libpqxx's exceptions into StoreError naming the server and what was done.
template <class F>
auto guarded(std::string_view shown_url, std::string_view what, F&& f) {
  try {
    return f();
  } catch (const StoreError&) {
    throw;
  } catch (const pqxx::sql_error& e) {
    throw StoreError(fmt::format("{}: {}: {} (SQLSTATE {})", shown_url, what,
                                 std::string_view(e.what()), e.sqlstate()));
  } catch (const std::exception& e) {
    // broken_connection and the like: libpq's text spans lines ("...failed: Connection
    // refused\n\tIs the server running...?\n"): one line, as every daq error.
    std::string text;
    for (const char c : std::string_view(e.what())) {
      if (c != '\n' && c != '\t')
        text += c;
      else if (!text.empty() && text.back() != ' ')
        text += ' ';
    }
    while (!text.empty() && text.back() == ' ') text.pop_back();
    throw StoreError(fmt::format("{}: {}: {}", shown_url, what, text));
  }
}

}  // namespace cal::storage::pg
