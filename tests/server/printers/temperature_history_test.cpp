// TemperatureHistory: one sample a second at most, half an hour kept; and the PrinterService
// filling it from a real simulated printer's reports while its events still reach the hub.
#include "server/printers/temperature_history.hpp"

#include <doctest/doctest.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "server/common/domain_error.hpp"
#include "server/printers/printer_service.hpp"
#include "tests/support/scratch_dir.hpp"

using namespace salient::server;
using namespace std::chrono_literals;

namespace {

TemperatureSample at(double t, double hotend) {
  TemperatureSample s;
  s.time = t;
  s.hotend.actual = hotend;
  s.hotend.target = 200;
  return s;
}

}  // namespace

TEST_CASE("samples a second apart at most, the last half hour kept, oldest first") {
  TemperatureHistory h;
  CHECK(h.due(1000));
  h.add(at(1000, 20));
  CHECK(!h.due(1000.5));
  h.add(at(1000.5, 21));  // too soon: dropped
  CHECK(h.due(1001));
  for (int i = 1; i <= 2000; ++i) h.add(at(1000 + i, 20 + i * 0.1));
  const auto s = h.samples(3000);
  REQUIRE(s.size() == 1801);  // 1200 … 3000, one a second
  CHECK(s.front().time == doctest::Approx(1200));
  CHECK(s.back().time == doctest::Approx(3000));
  CHECK(*s.back().hotend.actual == doctest::Approx(220));
  for (std::size_t i = 1; i < s.size(); ++i) CHECK(s[i].time > s[i - 1].time);
  CHECK(h.samples(5000).empty());  // nothing reported for an hour: nothing in the window
}

TEST_CASE("a clock set back starts again rather than leaving the samples out of order") {
  TemperatureHistory h;
  h.add(at(1000, 20));
  h.add(at(1001, 21));
  CHECK(h.due(500));
  h.add(at(500, 22));
  const auto s = h.samples(500);
  REQUIRE(s.size() == 1);
  CHECK(s[0].time == 500);
}

TEST_CASE("the printer service keeps each printer's reported temperatures and still publishes") {
  salient::test::ScratchDir dir("temperature-history");
  ::setenv("SALIENT_SIM", SALIENT_SIM_PROGRAM, 1);
  Store store(dir.path / "data");
  DaemonConfig config;
  config.printers[0].sim_args = "--advanced-ok --autoreport --time-scale 0 --heat-time-scale 0";
  std::atomic<int> published{0};
  PrinterEvents events;
  events.changed = [&](const Printer&, bool) { ++published; };
  PrinterService service(config, store, events);
  CHECK_THROWS_AS(service.temperatures("nope"), NotFound);
  service.start();
  const auto now = [] {
    return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  };
  const auto heated = [&] {
    for (const TemperatureSample& s : service.temperatures("sim").samples(now()))
      if (s.hotend.target && *s.hotend.target == 190 && s.hotend.actual && *s.hotend.actual > 100)
        return true;
    return false;
  };
  for (int i = 0; i < 300 && service.get("sim").state() != PrinterState::operational; ++i)
    std::this_thread::sleep_for(20ms);
  REQUIRE(service.get("sim").state() == PrinterState::operational);
  service.get("sim").command({"M104 S190"});
  for (int i = 0; i < 500 && !heated(); ++i) std::this_thread::sleep_for(20ms);
  CHECK(heated());
  const auto samples = service.temperatures("sim").samples(now());
  CHECK(samples.size() >= 2);
  for (std::size_t i = 1; i < samples.size(); ++i) CHECK(samples[i].time - samples[i - 1].time >= 1.0);
  CHECK(published > 0);
  service.stop();
}
