// What one node NOTIFYs and another reads back: an event or an interest, and nothing else taken
// from a channel anyone may NOTIFY on.
#include "server/events/relayed_event.hpp"

#include <doctest/doctest.h>

#include <stdexcept>

using namespace salient::server;

TEST_CASE("a relayed event reads back as it was sent, its own node's marked local") {
  const std::string text = encode_event("a", 7, {"printers", "printer/p1"}, "printer",
                                        R"({"state":"printing"})", Delivery::coalesce);
  const RelayMessage on_b = decode_relay_message(text, "b");
  REQUIRE(on_b.event);
  CHECK(on_b.event->node == "a");
  CHECK(on_b.event->type == "printer");
  CHECK(on_b.event->topics == std::vector<std::string>{"printers", "printer/p1"});
  CHECK(on_b.event->delivery == Delivery::coalesce);
  CHECK_FALSE(on_b.event->local);
  CHECK(decode_relay_message(text, "a").event->local);
}

TEST_CASE(
    "topics a node does not know are left out and the event goes to the others (refused when none is "
    "known)") {
  // A farm queue's change was published on "farm/PROFILE" too: the nodes dropped the whole event.
  const auto e = decode_relay_message(
      encode_event("a", 1, {"printers", "farm/generic-i3", "no such"}, "queue", "{}", Delivery::always), "b");
  REQUIRE(e.event);
  CHECK(e.event->topics == std::vector<std::string>{"printers"});
  CHECK_THROWS_AS(
      decode_relay_message(encode_event("a", 2, {"farm/x", "../etc"}, "queue", "{}", Delivery::always), "b"),
      std::invalid_argument);
}

TEST_CASE("anything else on the channel is refused, never a crash") {
  for (const std::string bad :
       {"", "no header line", "[1,2]\n{}", "{\"n\":\"a\"}\n{}",
        "{\"n\":\"a\",\"s\":1,\"t\":[\"jobs\"],\"y\":\"job\",\"v\":9}\n{}",
        "{\"n\":\"a\",\"s\":1,\"t\":\"jobs\",\"y\":\"job\",\"v\":0}\n{}", "{\"i\":5}\n"})
    CHECK_THROWS_AS(decode_relay_message(bad, "b"), std::invalid_argument);
  const auto interest = decode_relay_message(encode_interest("a", 3, {"terminal/p", "bogus"}), "b");
  CHECK_FALSE(interest.event);
  CHECK(interest.interest == std::vector<std::string>{"terminal/p"});
}
