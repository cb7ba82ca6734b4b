// The local API's request rules (see http_policy.hpp and docs/web.md).
#include "http_policy.hpp"

#include <algorithm>
#include <boost/beast/http/field.hpp>
#include <boost/beast/http/verb.hpp>
#include <boost/beast/websocket/rfc6455.hpp>
#include <cctype>
#include <charconv>
#include <cstdint>
#include <exception>
#include <random>

namespace cal::daq::web {
namespace {

namespace http = boost::beast::http;

// Beast 1.74 speaks boost::string_view; the rest of the code std::string_view.
std::string_view sv(boost::beast::string_view s) { return {s.data(), s.size()}; }

std::string lower(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

bool iequals(std::string_view a, std::string_view b) { return lower(a) == lower(b); }

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// Host header -> host name without the port ("[::1]:8080" -> "::1"), lower-case; nullopt
// when it is not of the form name[:digits].
std::optional<std::string> host_name(std::string_view host) {
  std::string_view name = host, port;
  if (host.starts_with('[')) {  // an IPv6 literal
    const auto close = host.find(']');
    if (close == std::string_view::npos) return std::nullopt;
    name = host.substr(1, close - 1);
    const auto rest = host.substr(close + 1);
    if (!rest.empty() && !rest.starts_with(':')) return std::nullopt;
    if (!rest.empty()) port = rest.substr(1);
  } else if (const auto colon = host.rfind(':'); colon != std::string_view::npos) {
    name = host.substr(0, colon);
    port = host.substr(colon + 1);
    if (port.empty()) return std::nullopt;
  }
  if (name.empty() || port.size() > 5) return std::nullopt;
  for (char c : port)
    if (c < '0' || c > '9') return std::nullopt;
  return lower(name);
}

Response refuse(int status, std::string_view why) { return {status, json_error(why)}; }

std::optional<std::string> bearer(std::string_view auth) {
  auth = trim(auth);
  const auto space = auth.find(' ');
  if (space == std::string_view::npos || !iequals(auth.substr(0, space), "bearer"))
    return std::nullopt;
  return std::string(trim(auth.substr(space + 1)));
}

bool authorised(const Header& h, const Policy& p) {
  if (p.token.empty()) return true;
  bool ok = false;
  // Both sources are compared whatever the first gave, so the time says nothing about which.
  if (const auto it = h.find(http::field::authorization); it != h.end())
    if (const auto b = bearer(sv(it->value()))) ok |= same_token(*b, p.token);
  if (const auto q = query_parameter(sv(h.target()), "token")) ok |= same_token(*q, p.token);
  return ok;
}

// 128 random bits in base64, for the page's script nonce.
std::string make_nonce() {
  static constexpr char digits[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::random_device random;
  std::string out;
  std::uint32_t bits = 0;
  int have = 0;
  for (int i = 0; i < 22; ++i) {  // 22 digits of 6 bits: 132 bits
    if (have < 6) bits = random(), have = 32;
    out += digits[bits & 63];
    bits >>= 6, have -= 6;
  }
  return out;
}

}  // namespace

std::string page_policy(std::string_view nonce) {
  // The page's own script (by its nonce) and nothing else; its style is inline; it talks to
  // its own server only (fetch and the WebSocket); nothing may frame it.
  return "default-src 'none'; script-src 'nonce-" + std::string(nonce) +
         "'; style-src 'unsafe-inline'; img-src data: blob:; connect-src 'self' blob:; "
         "base-uri 'none'; form-action 'none'; frame-ancestors 'none'";
}

bool same_token(std::string_view given, std::string_view expected) {
  // Every byte of `expected` is visited once; `given` is indexed modulo its length (or a
  // zero byte when empty), and the length difference is folded into the result.
  std::size_t diff = given.size() ^ expected.size();
  for (std::size_t i = 0; i < expected.size(); ++i) {
    const unsigned char g = given.empty() ? 0 : static_cast<unsigned char>(given[i % given.size()]);
    diff |= static_cast<unsigned char>(g ^ static_cast<unsigned char>(expected[i]));
  }
  return diff == 0 && !expected.empty();
}

std::optional<std::string> query_parameter(std::string_view target, std::string_view name) {
  const auto q = target.find('?');
  if (q == std::string_view::npos) return std::nullopt;
  std::string_view rest = target.substr(q + 1);
  while (!rest.empty()) {
    const auto amp = rest.find('&');
    const auto pair = rest.substr(0, amp);
    rest = amp == std::string_view::npos ? std::string_view{} : rest.substr(amp + 1);
    const auto eq = pair.find('=');
    if (pair.substr(0, eq) != name) continue;
    return percent_decoded(eq == std::string_view::npos ? std::string_view{} : pair.substr(eq + 1),
                           true);
  }
  return std::nullopt;
}

std::string percent_decoded(std::string_view raw, bool plus_is_space) {
  std::string value;
  for (std::size_t i = 0; i < raw.size(); ++i) {
    if (raw[i] == '%' && i + 2 < raw.size() && hex_digit(raw[i + 1]) >= 0 &&
        hex_digit(raw[i + 2]) >= 0) {
      value += static_cast<char>(hex_digit(raw[i + 1]) * 16 + hex_digit(raw[i + 2]));
      i += 2;
    } else {
      value += plus_is_space && raw[i] == '+' ? ' ' : raw[i];
    }
  }
  return value;
}

bool host_allowed(std::string_view host, std::string_view local_address, const Policy& p) {
  const auto name = host_name(trim(host));
  if (!name) return false;
  if (*name == "localhost" || *name == lower(local_address)) return true;
  return std::any_of(p.allowed_hosts.begin(), p.allowed_hosts.end(),
                     [&](const std::string& a) { return lower(a) == *name; });
}

std::string json_error(std::string_view message) {
  std::string out = R"({"error": ")";
  for (unsigned char c : message) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += static_cast<char>(c);
    } else if (c < 0x20 || c == 0x7f) {
      static constexpr char hex[] = "0123456789abcdef";
      out += "\\u00";
      out += hex[c >> 4];
      out += hex[c & 15];
    } else {
      out += static_cast<char>(c);
    }
  }
  return out + "\"}";
}

bool is_websocket_request(const Header& h) {
  const std::string_view target = sv(h.target());
  return boost::beast::websocket::is_upgrade(h) && target.substr(0, target.find('?')) == "/ws";
}

std::optional<Response> screen(const Header& h, std::string_view local_address, const Policy& p) {
  const auto host = h.find(http::field::host);
  if (host == h.end() || !host_allowed(sv(host->value()), local_address, p))
    return refuse(403,
                  "this server answers only to its own address, localhost or a name given "
                  "with --allow-host (Host header refused)");
  if (!authorised(h, p))
    return refuse(401, "missing or wrong token (Authorization: Bearer TOKEN, or ?token=)");
  if (const auto origin = h.find(http::field::origin); origin != h.end()) {
    if (!iequals(trim(sv(origin->value())), "http://" + std::string(trim(sv(host->value())))))
      return refuse(403, "cross-site request refused (Origin is not this page's)");
  }
  if (h.method() == http::verb::post) {
    const auto type = h.find(http::field::content_type);
    const std::string_view t = type == h.end() ? std::string_view{} : sv(type->value());
    if (!iequals(trim(t.substr(0, t.find(';'))), "application/json"))
      return refuse(415, "a POST body must be sent as Content-Type: application/json");
  }
  if (const auto length = h.find(http::field::content_length); length != h.end()) {
    // Beast has checked the syntax; a value that does not parse here counts as too large.
    const std::string_view l = trim(sv(length->value()));
    std::uint64_t n = 0;
    const auto [end, ec] = std::from_chars(l.data(), l.data() + l.size(), n);
    if (ec != std::errc{} || end != l.data() + l.size() || n > p.max_body_bytes)
      return refuse(413,
                    "request body over the " + std::to_string(p.max_body_bytes) + " byte limit");
  }
  return std::nullopt;
}

Response route(const Request& req, const Api& api) {
  const std::string_view target = sv(req.target());
  const std::string_view path = target.substr(0, target.find('?'));
  // HEAD is answered as GET; the server sends the header alone.
  const bool get = req.method() == http::verb::get || req.method() == http::verb::head,
             post = req.method() == http::verb::post;
  try {
    if (get && path == "/" && api.page) {
      const auto nonce = make_nonce();
      return {.status = 200,
              .body = api.page(nonce),
              .content_type = "text/html; charset=utf-8",
              .content_security_policy = page_policy(nonce)};
    }
    if (get && path == "/api/runs" && api.runs) return api.runs();
    if (get && path == "/api/status" && api.status) return api.status();
    if (post && path == "/api/runs/start" && api.start) return api.start(req.body());
    if (post && path == "/api/runs/stop" && api.stop) return api.stop(req.body());
    for (const auto& r : api.routes) {
      const bool method = (get && r.method == "GET") || (post && r.method == "POST");
      const bool under =
          r.path.ends_with('/') && path.starts_with(r.path) && path.size() > r.path.size();
      if (method && r.handle && (path == r.path || under)) return r.handle(path, req.body());
    }
  } catch (const std::exception& e) {
    return refuse(500, e.what());
  } catch (...) {
    return refuse(500, "internal error");
  }
  return refuse(404, "no such resource");
}

}  // namespace cal::daq::web
