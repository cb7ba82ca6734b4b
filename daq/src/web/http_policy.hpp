#pragma once
// What the local API accepts, as pure functions of a parsed request (no sockets), so that the
// rules are unit-tested and fuzzed apart from the server's I/O (docs/web.md, "Security"):
// - Host: the connection's local address, "localhost", or a name given with --allow-host;
//   anything else (a DNS-rebinding name) is refused with 403.
// - Origin, when a browser sends one: the page's own ("http://" + Host), else 403; "null"
//   is foreign. Requests without Origin (curl, scripts) are not browsers' cross-site requests.
// - Token (when configured): "Authorization: Bearer TOKEN" (the scheme in any case) or the
//   query parameter "token", compared in constant time whatever the lengths; else 401.
// - POST bodies: Content-Type application/json (415 otherwise: a text/plain "simple request"
//   needs no CORS preflight), at most max_body_bytes (413). These are decided from the header
//   alone, before any body byte is read.
// - Handlers' exceptions become 500 with a JSON error; nothing escapes to the event loop.
#include <boost/beast/http/message.hpp>
#include <boost/beast/http/string_body.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "server.hpp"

namespace cal::daq::web {

struct Policy {
  std::string token;                       // empty: no token required
  std::vector<std::string> allowed_hosts;  // beside localhost and the local address
  std::size_t max_body_bytes = 64 * 1024;
};

// Constant-time comparison: the time depends only on the length of `expected`, never on
// where `given` differs nor on its length.
bool same_token(std::string_view given, std::string_view expected);

// The value of query parameter `name` in a request target, percent-decoded; nullopt if absent.
std::optional<std::string> query_parameter(std::string_view target, std::string_view name);
// `raw` with each %XX replaced by its byte (and '+' by a space when `plus_is_space`: a query's
// form encoding, not a path's); a '%' not followed by two hex digits stays as it is.
std::string percent_decoded(std::string_view raw, bool plus_is_space);

// Whether a Host header value names this server: `local_address` is the connection's local
// address as text ("127.0.0.1", "::1"). The port, if any, is not compared.
bool host_allowed(std::string_view host, std::string_view local_address, const Policy& p);

// {"error": "..."} with the text escaped for JSON.
std::string json_error(std::string_view message);

using Header = boost::beast::http::request_header<>;
using Request = boost::beast::http::request<boost::beast::http::string_body>;

// Screens a request from its header alone; nullopt when its body may be read and the request
// routed, else the refusal to send (after which the connection is closed, the body unread).
std::optional<Response> screen(const Header& h, std::string_view local_address, const Policy& p);

// The page's Content-Security-Policy: only script elements carrying `nonce` run.
std::string page_policy(std::string_view nonce);

// Routes a screened, complete request to the API (HEAD as GET). Never throws: a handler's exception
// is a 500 naming it.
Response route(const Request& req, const Api& api);

// Whether the request asks for the WebSocket (GET /ws with an Upgrade).
bool is_websocket_request(const Header& h);

}  // namespace cal::daq::web
