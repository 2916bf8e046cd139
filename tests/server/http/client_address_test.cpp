#include "server/http/client_address.hpp"

#include <doctest/doctest.h>

#include <stdexcept>

using namespace salient::server;

TEST_CASE("client address: X-Forwarded-For is believed from trusted proxies only, right-most untrusted hop") {
  const TrustedProxies trusted({"127.0.0.1", "10.0.0.0/8", "fd00::/8"});
  CHECK(trusted.trusts("127.0.0.1"));
  CHECK(trusted.trusts("10.200.3.4"));
  CHECK(trusted.trusts("::ffff:10.1.1.1"));  // IPv4-mapped, as a dual-stack socket reports it
  CHECK(trusted.trusts("fd12::1"));
  CHECK(!trusted.trusts("11.0.0.1"));
  CHECK(!trusted.trusts("127.0.0.2"));
  CHECK(!trusted.trusts("garbage"));

  // An untrusted peer's header is ignored: a client cannot pick its own address.
  CHECK(client_address("203.0.113.9", "198.51.100.1", trusted) == "203.0.113.9");
  CHECK(client_address("127.0.0.1", "", trusted) == "127.0.0.1");
  CHECK(client_address("127.0.0.1", "198.51.100.7", trusted) == "198.51.100.7");
  // The client wrote the left part itself ("1.2.3.4"); nginx appended the address it saw.
  CHECK(client_address("127.0.0.1", "1.2.3.4, 198.51.100.7", trusted) == "198.51.100.7");
  // Two proxies of ours in a row: the right-most hop that is not one of them.
  CHECK(client_address("127.0.0.1", "1.2.3.4, 198.51.100.7, 10.0.0.5", trusted) == "198.51.100.7");
  CHECK(client_address("127.0.0.1", " 2001:db8::1 ", trusted) == "2001:db8::1");
  // A hop that is not an address stops the walk at the last one that was.
  CHECK(client_address("127.0.0.1", "198.51.100.7, unknown, 10.0.0.5", trusted) == "10.0.0.5");
  CHECK(client_address("127.0.0.1", "<script>", trusted) == "127.0.0.1");
  // No trusted proxies configured (the default): never believed.
  CHECK(client_address("127.0.0.1", "198.51.100.7", TrustedProxies()) == "127.0.0.1");

  CHECK_THROWS_AS(TrustedProxies({"localhost"}), std::invalid_argument);
  CHECK_THROWS_AS(TrustedProxies({"10.0.0.0/33"}), std::invalid_argument);
}

TEST_CASE("base path: a trusted proxy's X-Forwarded-Prefix or X-Script-Name, else the configured one") {
  CHECK(base_path_of(true, "/salient", "", "") == "/salient");
  CHECK(base_path_of(true, "/salient/", "", "") == "/salient");
  CHECK(base_path_of(true, "", "/octo", "") == "/octo");
  CHECK(base_path_of(false, "/evil", "", "/salient") == "/salient");
  CHECK(base_path_of(true, "http://evil/", "", "/salient") == "/salient");  // not a path
  CHECK(base_path_of(true, "/a/../b", "", "") == "");
  CHECK(normal_base_path("/") == std::string());
  CHECK(!normal_base_path("salient"));
}
