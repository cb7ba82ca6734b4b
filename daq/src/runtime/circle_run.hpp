#pragma once
// One ballbar circular test, acquired: the bar's gauge instrument streams readings, every
// reading is stored raw, the BallbarSegmenter finds the feed-in and cuts the two traces, and
// the ISO 230-4 / diagnostics result is stored with the run.
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "cal/analysis/circle.hpp"
#include "cal/daq/ballbar.hpp"
#include "cal/daq/config.hpp"
#include "cal/drivers/instrument.hpp"

namespace boost::asio {
class io_context;
}

namespace daq {

struct CircleRunSetup {
  cal::daq::Config config;  // machine, campaign
  cal::daq::BallbarProgram program;
  std::string plane = "XY";
  std::filesystem::path database;
  std::unique_ptr<cal::drivers::Instrument> ballbar;
  std::string capture_path;
  std::string software_version = "daq 0.1.0";
  std::function<void(const std::string&)> on_event;
};

struct CircleRunOutcome {
  std::int64_t run_id = 0;
  bool complete = false;
  std::string reason;
  std::optional<cal::circle::Result> result;
  std::size_t readings = 0;
};

class CircleRun {
 public:
  CircleRun(boost::asio::io_context& io, CircleRunSetup setup);
  ~CircleRun();
  void start();
  void stop(const std::string& reason);
  bool finished() const;
  const CircleRunOutcome& outcome() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace daq
