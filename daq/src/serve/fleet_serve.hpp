#pragma once
// `daq serve --db postgresql://...`: the fleet view of a central store (docs/web.md, "The fleet
// view"). A reader only: no set-up, no instruments, no acquisition, and every request that would
// write (any POST) is refused with 403 saying why. The store is read by storage/pg's fleet queries.
#include "serve/service.hpp"

namespace daq::serve {

// Runs until SIGINT or SIGTERM. Throws cal::storage::StoreError when the central store cannot be
// read at start (absent server, not a caldaq store, another schema version), and cal::InputError
// for options that would make it write or acquire (-c, --simulate, --capture-dir).
void serve_fleet(const ServeOptions& o);

}  // namespace daq::serve
