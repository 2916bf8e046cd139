#include "server/config/daemon_config.hpp"

#include <doctest/doctest.h>

#include "core/common/input_error.hpp"

using namespace salient::server;
using salient::core::InputError;

TEST_CASE("the shipped config/salientd.toml is exactly the embedded defaults") {
  const DaemonConfig shipped = load_daemon_config(SALIENT_SOURCE_DIR "/config/salientd.toml");
  const DaemonConfig d = default_daemon_config();
  CHECK(shipped.listen == d.listen);
  CHECK(shipped.data_dir == d.data_dir);
  CHECK(shipped.max_upload_bytes == d.max_upload_bytes);
  CHECK(shipped.max_json_bytes == d.max_json_bytes);
  CHECK(shipped.max_json_depth == d.max_json_depth);
  CHECK(shipped.workers == d.workers);
  CHECK(shipped.queue_limit == d.queue_limit);
  CHECK(shipped.request_timeout_seconds == d.request_timeout_seconds);
  CHECK(shipped.max_connections == d.max_connections);
  CHECK(shipped.max_connections_per_address == d.max_connections_per_address);
  CHECK(shipped.max_bodies_in_flight_bytes == d.max_bodies_in_flight_bytes);
  CHECK(shipped.web_vendor_dir == d.web_vendor_dir);
  CHECK(shipped.node.id == d.node.id);
  CHECK(shipped.node.lease_seconds == d.node.lease_seconds);
  CHECK(shipped.node.max_attempts == d.node.max_attempts);
  CHECK((shipped.node.roles.api && shipped.node.roles.slicer && shipped.node.roles.printers));
  REQUIRE(shipped.printers.size() == 1);
  CHECK(shipped.printers[0].id == "sim");
  CHECK(shipped.printers[0].kind == PrinterKind::sim);
  CHECK(shipped.printers[0].sim_args == d.printers[0].sim_args);
  CHECK(shipped.printers[0].autoconnect == d.printers[0].autoconnect);
  CHECK(shipped.printers[0].profile == d.printers[0].profile);
  CHECK(d.listen.rfind("127.0.0.1:", 0) == 0);  // loopback unless configured
}

TEST_CASE("a config with serial and TCP printers") {
  const DaemonConfig c = parse_daemon_config(R"(
[server]
listen = "0.0.0.0:9000"
[jobs]
workers = 2
[web]
vendor_dir = "/opt/js"
[[printers]]
id = "ender"
kind = "serial"
port = "/dev/ttyUSB0"
baud = 115200
profile = "ender3"
[[printers]]
id = "bridge"
kind = "tcp"
port = "10.0.0.5:2000"
)",
                                             "salientd.toml");
  CHECK(c.listen == "0.0.0.0:9000");
  CHECK(c.workers == 2);
  CHECK(c.web_vendor_dir == "/opt/js");
  REQUIRE(c.printers.size() == 2);
  CHECK(c.printers[0].baud == 115200);
  CHECK(c.printers[1].port == "10.0.0.5:2000");
  CHECK(c.printers[0].kind == PrinterKind::serial);
  CHECK(c.printers[1].kind == PrinterKind::tcp);
}

TEST_CASE("mistakes name the file, the line and the key") {
  CHECK_THROWS_WITH_AS(parse_daemon_config("[server]\nlisten = \"x\"\nport = 80\n", "d.toml"),
                       "d.toml:3: unknown key 'server.port'", InputError);
  CHECK_THROWS_WITH_AS(parse_daemon_config("[jobs]\nworkers = 0\n", "d.toml"),
                       "d.toml:2: 'jobs.workers' must be between 1 and 64", InputError);
  CHECK_THROWS_WITH_AS(parse_daemon_config("[jobs]\nworkers = \"two\"\n", "d.toml"),
                       "d.toml:2: 'jobs.workers' must be a whole number", InputError);
  CHECK_THROWS_WITH_AS(parse_daemon_config("[[printers]]\nid = \"a\"\nkind = \"serial\"\n", "d.toml"),
                       "d.toml:1: printer 'a' needs a 'port'", InputError);
  CHECK_THROWS_WITH_AS(parse_daemon_config("[[printers]]\nid = \"a\"\n[[printers]]\nid = \"a\"\n", "d.toml"),
                       "d.toml:3: printer id 'a' appears twice", InputError);
  CHECK_THROWS_WITH_AS(parse_daemon_config("[[printers]]\nid = \"../x\"\n", "d.toml"),
                       doctest::Contains("'printers.id' must be lower-case letters"), InputError);
  CHECK_THROWS_WITH_AS(parse_daemon_config("colour = 1\n", "d.toml"), "d.toml:1: unknown key 'colour'",
                       InputError);
  // Found by config_fuzz: a huge number was cast to a size (undefined behaviour), now it is refused.
  CHECK_THROWS_WITH_AS(parse_daemon_config("[server]\nmax_json_kb = 1e300\n", "d.toml"),
                       "d.toml:2: 'server.max_json_kb' must be between 1 and 1.04858e+06", InputError);
  CHECK_THROWS_AS(parse_daemon_config("[server]\nrequest_timeout_seconds = 0.1\n", "d.toml"), InputError);
  CHECK_THROWS_AS(parse_daemon_config("[server]\nmax_connections = 0\n", "d.toml"), InputError);
  CHECK_THROWS_WITH_AS(parse_daemon_config("[[printers]]\nid = \"a\"\nsim_args = \"--log 'x\"\n", "d.toml"),
                       "d.toml:1: 'printers.sim_args': unclosed quote in '--log 'x'", InputError);
  CHECK_THROWS_AS(
      parse_daemon_config("[server]\nmax_upload_mb = 100\nmax_bodies_in_flight_mb = 50\n", "d.toml"),
      InputError);
  CHECK_THROWS_AS(parse_daemon_config("[server\n", "d.toml"), InputError);
  CHECK_THROWS_WITH_AS(load_daemon_config("/no/such/salientd.toml"),
                       "/no/such/salientd.toml: cannot open for reading", InputError);
}

TEST_CASE("a Replicator profile's printer speaks s3g at 115200 unless told otherwise") {
  const DaemonConfig c = parse_daemon_config(R"(
[[printers]]
id = "r2x"
profile = "replicator2x"
[[printers]]
id = "r2x-marlin"
profile = "replicator2x"
protocol = "marlin"
baud = 250000
sim_args = "--time-scale 0"
[[printers]]
id = "ender"
profile = "ender3"
[[printers]]
id = "forced"
profile = "ender3"
protocol = "s3g"
machine = "r2"
)",
                                             "d.toml");
  REQUIRE(c.printers.size() == 4);
  CHECK(c.printers[0].protocol == PrinterProtocol::s3g);
  CHECK(c.printers[0].baud == 115200);
  CHECK(c.printers[0].sim_args.find("--firmware sailfish") != std::string::npos);
  CHECK(c.printers[0].machine == "r2x");
  CHECK(c.printers[1].protocol == PrinterProtocol::marlin);
  CHECK(c.printers[1].baud == 250000);
  CHECK(c.printers[1].sim_args == "--time-scale 0");
  CHECK(c.printers[2].protocol == PrinterProtocol::marlin);
  CHECK(c.printers[2].baud == 250000);
  CHECK(c.printers[2].sim_args == default_sim_args(PrinterProtocol::marlin));
  CHECK(c.printers[3].protocol == PrinterProtocol::s3g);
  CHECK(c.printers[3].machine == "r2");
  CHECK_THROWS_WITH_AS(
      parse_daemon_config("[[printers]]\nid = \"a\"\nprotocol = \"s3g\"\nmachine = \"r1\"\n", "d.toml"),
      "d.toml:1: 'printers.machine' must be one of r2, r2h, r2x, got 'r1'", InputError);
  CHECK_THROWS_WITH_AS(parse_daemon_config("[[printers]]\nid = \"a\"\nprotocol = \"x3g\"\n", "d.toml"),
                       "d.toml:1: 'printers.protocol' must be marlin or s3g, got 'x3g'", InputError);
}

TEST_CASE("the store section names the database and the shared files, else SQLite is in the data dir") {
  CHECK(default_daemon_config().store_url.empty());
  CHECK(default_daemon_config().store_files.empty());
  const DaemonConfig c = parse_daemon_config(
      "[store]\nurl = \"postgresql://salient@db.farm/salient\"\nfiles = \"/srv/salient-files\"\n", "d.toml");
  CHECK(c.store_url == "postgresql://salient@db.farm/salient");
  CHECK(c.store_files == "/srv/salient-files");
  CHECK_THROWS_WITH_AS(parse_daemon_config("[store]\nurl = \"mysql://db/x\"\n", "d.toml"),
                       doctest::Contains("'store.url': unknown database URL scheme 'mysql'"), InputError);
  CHECK_THROWS_WITH_AS(parse_daemon_config("[store]\nuri = \"x\"\n", "d.toml"),
                       "d.toml:2: unknown key 'store.uri'", InputError);
}

TEST_CASE("the node section gives the farm id and roles, and without it a node has every role") {
  const DaemonConfig d = default_daemon_config();
  CHECK(d.node.id.empty());
  CHECK((d.node.roles.api && d.node.roles.slicer && d.node.roles.printers));
  CHECK(!default_node_id().empty());
  const DaemonConfig c = parse_daemon_config(
      "[node]\nid = \"farm-b\"\nroles = [\"slicer\", \"printers\"]\nlease_seconds = 4\nmax_attempts = 5\n",
      "d.toml");
  CHECK(c.node.id == "farm-b");
  CHECK(!c.node.roles.api);
  CHECK(c.node.roles.slicer);
  CHECK(c.node.roles.printers);
  CHECK(c.node.lease_seconds == 4);
  CHECK(c.node.max_attempts == 5);
  CHECK_THROWS_WITH_AS(parse_daemon_config("[node]\nroles = [\"api\", \"web\"]\n", "d.toml"),
                       doctest::Contains("'node.roles' entries are"), InputError);
  CHECK_THROWS_WITH_AS(parse_daemon_config("[node]\nroles = []\n", "d.toml"),
                       doctest::Contains("'node.roles' is empty"), InputError);
  CHECK_THROWS_WITH_AS(parse_daemon_config("[node]\nid = \"a b\"\n", "d.toml"),
                       doctest::Contains("'node.id'"), InputError);
  CHECK_THROWS_WITH_AS(parse_daemon_config("[node]\nlease_seconds = 0\n", "d.toml"),
                       doctest::Contains("node.lease_seconds"), InputError);
}

TEST_CASE("the farm's example configs load: an api node without printers, a printers node") {
  const DaemonConfig api = load_daemon_config(SALIENT_SOURCE_DIR "/deploy/farm/api.toml");
  CHECK(api.node.id == "api-1");
  CHECK((api.node.roles.api && api.node.roles.slicer && !api.node.roles.printers));
  CHECK(api.printers.empty());
  CHECK(api.store_url.rfind("postgresql://", 0) == 0);
  const DaemonConfig shelf = load_daemon_config(SALIENT_SOURCE_DIR "/deploy/farm/printers.toml");
  CHECK(shelf.node.id == "shelf-a");
  CHECK((!shelf.node.roles.api && shelf.node.roles.slicer && shelf.node.roles.printers));
  CHECK(shelf.printers.size() == 2);
  CHECK(shelf.store_url == api.store_url);
}
