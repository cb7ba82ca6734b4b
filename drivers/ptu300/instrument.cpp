// Vaisala PTU300 instrument (codec: ptu300/codec.hpp).
#include "ptu300/instrument.hpp"

#include <fmt/format.h>

#include <set>
#include <string>
#include <vector>

#include "instrument_core.hpp"

namespace cal::drivers {
namespace {

class Ptu300 final : public detail::InstrumentCore {
 public:
  Ptu300(boost::asio::io_context& io, std::unique_ptr<transport::Transport> t, InstrumentOptions o,
         codec::Ptu300Config config)
      : InstrumentCore(io, std::move(t), std::move(o)),
        config_(std::move(config)),
        codec_(config_) {}

  const codec::CodecStats& codec_stats() const override { return codec_.stats(); }

 private:
  void on_connected() override {
    codec_ = codec::Ptu300Codec(config_);
    send(codec::ptu300_stop());  // a unit left in RUN mode would interleave its own lines
    start_polling();
  }
  void on_poll() override {
    sent_ns_ = now_ns();
    send(codec::ptu300_send());
  }
  void on_bytes(std::span<const std::byte> bytes) override {
    decode(codec_, bytes, frames_);
    const std::int64_t t = now_ns();
    for (const auto& f : frames_) {
      ptu300::for_each_reading(
          f, [&](Quantity q, double v) { emit({.time_ns = t, .quantity = q, .value = v}); });
      say_unavailable(f);
    }
  }

  // A value printed as stars is no reading; the run hears why once, not every second, and
  // hears when the value is back.
  void say_unavailable(const codec::Ptu300Frame& f) {
    using Severity = DeviceMessage::Severity;
    for (const auto& field : f.fields) {
      const auto text = ptu300::unavailable_text(field);
      const std::string key = field.label + "/" + field.unit;
      if (text && starred_.insert(key).second)
        report_message({Severity::warning, 0, *text});
      else if (field.available && starred_.erase(key) > 0)
        report_message(
            {Severity::info, 0,
             fmt::format("{}: measured again", field.label.empty() ? field.unit : field.label)});
    }
  }

  codec::Ptu300Config config_;
  codec::Ptu300Codec codec_;
  std::vector<codec::Ptu300Frame> frames_;
  std::int64_t sent_ns_ = 0;
  std::set<std::string> starred_;  // fields printed as stars, said once (label/unit)
};

}  // namespace

namespace ptu300 {
std::optional<std::string> unavailable_text(const codec::Ptu300Field& field) {
  using Q = codec::Ptu300Quantity;
  if (field.available) return std::nullopt;
  if (field.quantity != Q::pressure && field.quantity != Q::temperature &&
      field.quantity != Q::relative_humidity && field.quantity != Q::dew_point)
    return std::nullopt;
  return fmt::format(
      "{}: printed as stars, no value (the PTU300 could not give it: a failed measurement, a "
      "check such as PDMAX exceeded, or the start-up; its ERRS command lists the errors)",
      field.label.empty() ? "the " + field.unit + " field" : field.label);
}
}  // namespace ptu300

std::unique_ptr<Instrument> make_ptu300(boost::asio::io_context& io,
                                        std::unique_ptr<transport::Transport> transport,
                                        InstrumentOptions options, codec::Ptu300Config config) {
  return std::make_unique<Ptu300>(io, std::move(transport), std::move(options), std::move(config));
}

}  // namespace cal::drivers
