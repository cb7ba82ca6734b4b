// SIMULATED TEMPer (see twin.hpp): answers the three output reports of OpenBSD's ugold(4) and
// urwen/temper (init 01 82 77 01, firmware 01 86 ff 01, data 01 80 33 01) with 8-byte input
// reports in the layout of the configured family.
#include "temper/twin.hpp"

#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>
#include <cmath>

namespace cal::drivers::sim {
namespace {

using Report = std::array<std::uint8_t, 8>;

void put16(Report& r, std::size_t at, std::int64_t v) {
  const auto u = static_cast<std::uint16_t>(static_cast<std::int16_t>(v));
  r[at] = static_cast<std::uint8_t>(u >> 8);
  r[at + 1] = static_cast<std::uint8_t>(u & 0xff);
}

}  // namespace

struct TemperTwin::Impl {
  Impl(World& w, Clock c, TemperTwinConfig cfg)
      : world(w), clock(std::move(c)), config(std::move(cfg)) {
    if (const auto* m = codec::temper_model_of(config.firmware)) model = *m;
  }

  // The input reports answering one output report (hidapi's report ID first).
  std::vector<Report> answer(std::span<const std::byte> out) {
    if (out.size() < 3) return {};
    const auto cmd = static_cast<std::uint8_t>(out[2]);
    if (cmd == 0x82) {
      const int n = (model.inner ? 1 : 0) + (model.probe ? 1 : 0);
      return {Report{0x82, static_cast<std::uint8_t>(n), 0x01, 0, 0, 0, 0, 0}};
    }
    if (cmd == 0x86) {
      std::string s = config.firmware;
      s.resize(16, '\0');
      Report a{}, b{};
      for (std::size_t i = 0; i < 8; ++i) {
        a[i] = static_cast<std::uint8_t>(s[i]);
        b[i] = static_cast<std::uint8_t>(s[8 + i]);
      }
      if (++firmware_queries <= config.half_firmware_answers) return {b};
      return {a, b};
    }
    if (cmd != 0x80) return {};
    const double now = clock();
    world.advance_to(now);
    const auto air = world.air().sample(now);
    const double inner_degc = air.temperature_degc;
    const double probe_degc = world.state().machine_temperature_degc;
    std::vector<Report> out_reports;
    const auto value_of = [&](int channel) { return channel == 0 ? inner_degc : probe_degc; };
    switch (model.family) {
      case codec::TemperFamily::ds75: {  // one report: 80 LL a b, 1/256 degC, 12 bits
        const auto& slots = model.ds75_slots;
        Report r{0x80, static_cast<std::uint8_t>(slots[1] >= 0 ? 4 : 2)};
        const auto ds75 = [](double t) { return std::llround(t * 16.0) * 16; };
        for (std::size_t k = 0; k < 2; ++k)
          if (slots[k] >= 0) put16(r, 2 + 2 * k, ds75(value_of(slots[k])));
        out_reports.push_back(r);
        break;
      }
      case codec::TemperFamily::gold:  // a report per sensor: 80 SS th tl, /100
        if (model.inner) {
          Report r{0x80, 0x80};
          put16(r, 2, std::llround(inner_degc * 100.0));
          out_reports.push_back(r);
        }
        if (model.probe) {
          Report r{0x80, 0x01};
          put16(r, 2, std::llround(probe_degc * 100.0));
          out_reports.push_back(r);
        }
        break;
      default: {  // temperx: 80 80 th tl hh hl, /100 (other layouts are not simulated)
        Report r{0x80, 0x80};
        put16(r, 2, std::llround(inner_degc * 100.0));
        put16(r, 4, std::llround(air.humidity_pct * 100.0));
        out_reports.push_back(r);
        if (model.probe) {  // TEMPerX_V3.3 on a stick with a probe: 80 01 th tl 4e 20
          Report p{0x80, 0x01};
          put16(p, 2, std::llround(probe_degc * 100.0));
          put16(p, 4, 20000);  // the 200.00 filler of urwen/temper PR #16's trace
          out_reports.push_back(p);
        }
        break;
      }
    }
    return out_reports;
  }

  World& world;
  Clock clock;
  TemperTwinConfig config;
  // Unknown firmware: a two-sensor gold stick.
  codec::TemperModel model{"", codec::TemperFamily::gold, true, true, false, {0, 1}, ""};
  std::uint64_t sent = 0;
  int firmware_queries = 0;
  std::uint64_t generation = 0;  // unplug() ends the transports of earlier generations
};

namespace {

class TwinHidTransport final : public transport::Transport {
 public:
  TwinHidTransport(boost::asio::io_context& io, std::weak_ptr<TemperTwin::Impl> twin)
      : io_(io), twin_(std::move(twin)) {}
  ~TwinHidTransport() override { close(); }

  void open(Handlers handlers) override {
    close();
    handlers_ = std::make_shared<Handlers>(std::move(handlers));
    const auto twin = twin_.lock();
    if (!twin) return post_error("TEMPer twin: not there");
    generation_ = twin->generation;
    boost::asio::post(io_, [h = handlers_] {
      if (h->opened) h->opened();
    });
  }
  void write(std::span<const std::byte> bytes) override {
    const auto twin = twin_.lock();
    if (!handlers_) return;
    if (!twin || twin->generation != generation_) return post_error("TEMPer twin: unplugged");
    for (const auto& r : twin->answer(bytes)) {
      ++twin->sent;
      boost::asio::post(io_, [h = std::weak_ptr<Handlers>(handlers_), r] {
        if (auto handlers = h.lock(); handlers && handlers->data)
          handlers->data(std::as_bytes(std::span(r)));
      });
    }
  }
  void close() override { handlers_.reset(); }
  bool is_open() const override { return handlers_ != nullptr; }
  std::string describe() const override { return "hid (simulated TEMPer)"; }

 private:
  void post_error(std::string message) {
    boost::asio::post(io_, [h = std::weak_ptr<Handlers>(handlers_), message] {
      if (auto handlers = h.lock(); handlers && handlers->error)
        handlers->error({transport::ErrorKind::read_failed, message});
    });
    handlers_.reset();
  }

  boost::asio::io_context& io_;
  std::weak_ptr<TemperTwin::Impl> twin_;
  std::shared_ptr<Handlers> handlers_;
  std::uint64_t generation_ = 0;
};

}  // namespace

TemperTwin::TemperTwin(boost::asio::io_context&, World& world, Clock clock, TemperTwinConfig config)
    : impl_(std::make_shared<Impl>(world, std::move(clock), std::move(config))) {}
TemperTwin::~TemperTwin() = default;
std::unique_ptr<transport::Transport> TemperTwin::connect(boost::asio::io_context& io) {
  return std::make_unique<TwinHidTransport>(io, impl_);
}
void TemperTwin::unplug() { ++impl_->generation; }
std::uint64_t TemperTwin::reports_sent() const { return impl_->sent; }
int TemperTwin::firmware_queries() const { return impl_->firmware_queries; }

}  // namespace cal::drivers::sim
