// Two nodes' PrinterServices on one store (each its own connections), each with a real simulated
// printer of one profile, taking the profile's farm-wide queue at the same moments: every entry
// starts exactly once (an entry is taken out of its queue before it starts).
#include <doctest/doctest.h>

#include <atomic>
#include <chrono>
#include <map>
#include <thread>

#include "server/common/domain_error.hpp"
#include "server/printers/printer_service.hpp"
#include "server/store/print_store.hpp"
#include "server/store/queue_store.hpp"
#include "tests/support/scratch_dir.hpp"

using namespace salient::server;
using namespace std::chrono_literals;

namespace {

DaemonConfig node_with(const std::string& id, const std::filesystem::path& dir) {
  DaemonConfig c;
  PrinterConfig p;
  p.id = id;
  p.profile = "generic-i3";
  p.sim_args = "--advanced-ok --time-scale 0 --log " + (dir / ("sim-" + id + ".log")).string();
  c.printers = {p};
  return c;
}

bool wait_operational(Printer& p, std::chrono::seconds limit = 30s) {
  const auto until = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < until) {
    if (p.state() == PrinterState::operational) return true;
    std::this_thread::sleep_for(5ms);
  }
  return false;
}

}  // namespace

TEST_CASE("farm queue: two nodes taking one profile's entries at the same moments start each once") {
  const salient::test::ScratchDir dir("farm-queue-take");
  ::setenv("SALIENT_SIM", SALIENT_SIM_PROGRAM, 1);
  Store store(dir.path / "data");
  constexpr int kEntries = 12;
  for (int i = 0; i < kEntries; ++i) {
    std::string gcode;
    for (int l = 0; l < 20; ++l) gcode += "G1 X" + std::to_string(10 + i) + " Y" + std::to_string(l) + "\n";
    const std::string name = "f" + std::to_string(i) + ".gcode";
    PrintStore(store.db()).put_file(name, store.files().put(gcode), static_cast<long long>(gcode.size()), i);
    QueueStore(store.db()).add("profile/generic-i3", "file", name, i);
  }
  PrinterService a(node_with("a", dir.path), store), b(node_with("b", dir.path), store);
  a.start();
  b.start();
  REQUIRE(wait_operational(a.get("a")));
  REQUIRE(wait_operational(b.get("b")));

  std::atomic<int> arrived{0};
  const auto take_all = [&](PrinterService& service, const std::string& id) {
    Printer& printer = service.get(id);
    for (int r = 1; r <= kEntries; ++r) {
      wait_operational(printer);
      ++arrived;
      while (arrived.load() < 2 * r) std::this_thread::yield();  // both ask at the same moment
      try {
        service.next(printer);
      } catch (const Conflict&) {  // nothing left, or busy
      }
    }
  };
  std::thread ta([&] { take_all(a, "a"); });
  std::thread tb([&] { take_all(b, "b"); });
  ta.join();
  tb.join();
  REQUIRE(wait_operational(a.get("a")));
  REQUIRE(wait_operational(b.get("b")));

  std::map<std::string, int> printed;
  for (const std::string id : {"a", "b"})
    for (const PrintRecord& p : PrintStore(store.db()).list(id, 100)) ++printed[p.filename];
  CHECK(printed.size() == kEntries);
  for (const auto& [name, times] : printed)
    CHECK_MESSAGE(times == 1, name << " started " << times << " times");
  CHECK(QueueStore(store.db()).list("profile/generic-i3").empty());
  a.stop();
  b.stop();
}
