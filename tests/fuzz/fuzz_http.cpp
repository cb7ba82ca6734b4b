// HTTP request handling on arbitrary bytes: Beast's parser with the server's limits, then
// our screening (Host, Origin, token, Content-Type, size) and routing to a stub API, exactly
// as the server does between reading and answering. Never a crash or an exception; every
// answer has a status the server may send, and a refused request never reaches the API.
#include <boost/beast/core/flat_buffer.hpp>
#include <boost/beast/http.hpp>
#include <string>

#include "http_policy.hpp"

namespace http = boost::beast::http;
using cal::daq::web::Response;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const cal::daq::web::Policy policy{
      .token = "s3cret", .allowed_hosts = {"machine.local"}, .max_body_bytes = 1024};
  bool reached = false;
  const cal::daq::web::Api api{
      .page = [&](std::string_view) { return reached = true, std::string("<html></html>"); },
      .runs =
          [&] {
            return reached = true, Response{200, "{}"};
          },
      .status =
          [&] {
            return reached = true, Response{200, "{}"};
          },
      .start =
          [&](const std::string& b) {
            return reached = true, Response{202, b};
          },
      .stop = [&](const std::string&) -> Response { throw std::runtime_error("stub store"); }};
  http::request_parser<http::empty_body> header;
  header.header_limit(512);
  boost::beast::error_code ec;
  std::size_t used = header.put(boost::asio::buffer(data, size), ec);
  if (ec || !header.is_header_done()) return 0;
  const auto refusal = cal::daq::web::screen(header.get(), "127.0.0.1", policy);
  if (refusal) {
    if (refusal->status != 401 && refusal->status != 403 && refusal->status != 413 &&
        refusal->status != 415)
      __builtin_trap();
    return 0;
  }
  if (cal::daq::web::is_websocket_request(header.get())) return 0;
  http::request_parser<http::string_body> body(std::move(header));
  body.body_limit(policy.max_body_bytes);
  body.eager(true);
  while (!body.is_done() && used < size) {
    const std::size_t n = body.put(boost::asio::buffer(data + used, size - used), ec);
    if (ec || n == 0) break;
    used += n;
  }
  if (!body.is_done() && (!ec || ec == http::error::need_more)) body.put_eof(ec);
  if (ec || !body.is_done()) return 0;
  const Response r = cal::daq::web::route(body.get(), api);
  if (r.status < 200 || r.status > 599 || (r.status == 404 && reached)) __builtin_trap();
  return 0;
}
