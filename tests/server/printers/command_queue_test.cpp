// CommandQueue: what a printer's thread takes next, whatever order the requests came in.
#include "server/printers/command_queue.hpp"

#include <doctest/doctest.h>

using namespace salient::server;

namespace {

template <typename T>
bool next_is(CommandQueue& q, bool linked = true) {
  const auto c = q.take(linked);
  return c && std::holds_alternative<T>(*c);
}

}  // namespace

TEST_CASE(
    "without a link only a connect goes, with one a disconnect, an e-stop, console batches, then the print") {
  CommandQueue q;
  q.push(ConsoleCommand{{"G28"}});
  q.push(ConsoleCommand{{"M105"}});
  q.push(PrintCommand{{std::nullopt, "digest", "a.gcode", 0}, 7});
  q.push(EmergencyStopCommand{});
  CHECK(!q.take(false));  // nothing of that can go before the link is up
  q.push(ConnectCommand{});
  CHECK(next_is<ConnectCommand>(q, false));
  q.push(DisconnectCommand{});
  CHECK(next_is<DisconnectCommand>(q));
  CHECK(next_is<EmergencyStopCommand>(q));
  CHECK(q.print_waiting());
  // A home asked for before the print goes before it: after it, it would move the head over the
  // finished part.
  const auto first = q.take(true);
  REQUIRE(first);
  CHECK(std::get<ConsoleCommand>(*first).lines == std::vector<std::string>{"G28"});
  CHECK(std::get<ConsoleCommand>(*q.take(true)).lines == std::vector<std::string>{"M105"});
  const auto p = q.take(true);
  REQUIRE(p);
  CHECK(std::get<PrintCommand>(*p).print_id == 7);
  CHECK(!q.print_waiting());
  CHECK(!q.take(true));
  CHECK(q.empty());
}

TEST_CASE("a waiting print can be taken back (a cancel before it streams), the console batches stay") {
  CommandQueue q;
  q.push(ConsoleCommand{{"G28"}});
  q.push(PrintCommand{{std::nullopt, "digest", "a.gcode", 0}, 7});
  const auto back = q.take_print();
  REQUIRE(back);
  CHECK(back->print_id == 7);
  CHECK(!q.print_waiting());
  CHECK(!q.take_print());
  CHECK(std::get<ConsoleCommand>(*q.take(true)).lines == std::vector<std::string>{"G28"});
  q.push(PrintCommand{{std::nullopt, "digest", "b.gcode", 0}, 8});
  q.push(ConsoleCommand{{"M105"}});
  // Held (paused before it began): console batches for now go, the print waits.
  CHECK(std::get<ConsoleCommand>(*q.take(true, true)).lines == std::vector<std::string>{"M105"});
  CHECK(!q.take(true, true));
  CHECK(q.print_waiting());
  CHECK(next_is<PrintCommand>(q));
  CHECK(q.empty());
}

TEST_CASE(
    "a disconnect drops a waiting connect and the other way round, and a linked printer drops a connect") {
  CommandQueue q;
  q.push(ConnectCommand{});
  q.push(DisconnectCommand{});
  CHECK(!q.connect_waiting());
  CHECK(!q.take(false));
  q.push(ConnectCommand{});
  CHECK(q.connect_waiting());
  CHECK(!q.take(true));  // connected already: nothing to do
  CHECK(!q.connect_waiting());
  q.push(DisconnectCommand{});
  q.push(ConnectCommand{});
  CHECK(!q.take(true));  // the connect undid the disconnect
}

TEST_CASE("console batches are bounded, and a closed connection carries nothing over") {
  CommandQueue q;
  for (std::size_t i = 0; i < CommandQueue::kMaxConsoleBatches; ++i) {
    CHECK(!q.console_full());
    q.push(ConsoleCommand{{"M105"}});
  }
  CHECK(q.console_full());
  q.push(EmergencyStopCommand{});
  q.push(PrintCommand{});
  q.clear();
  CHECK(q.empty());
  CHECK(!q.take(true));
}
