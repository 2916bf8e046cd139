#include "tests/support/test_database.hpp"

#include <libpq-fe.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string>

namespace salient::test {
namespace {

std::string env(const char* name) {
  const char* v = std::getenv(name);
  return v ? v : "";
}

std::string first_line(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  return line;
}

// The cluster's base URL, or the test is skipped (exit 77, CTest's SKIP_RETURN_CODE) with why.
std::string cluster_url() {
  if (std::string url = env("SALIENT_TEST_PG_URL"); !url.empty()) return url;
  std::string dir = env("SALIENT_TEST_PG_DIR");
#ifdef SALIENT_TEST_PG_DIR
  if (dir.empty()) dir = SALIENT_TEST_PG_DIR;
#endif
  if (!dir.empty())
    if (std::string url = first_line(std::filesystem::path(dir) / "url"); !url.empty()) return url;
  std::string why = dir.empty() ? "" : first_line(std::filesystem::path(dir) / "skip");
  if (why.empty())
    why = "no PostgreSQL for the tests: set SALIENT_TEST_PG_URL, or run tests/support/pg_cluster.sh";
  std::fprintf(stderr, "skipped: %s\n", why.c_str());
  std::exit(77);
}

void create_database(const std::string& base, const std::string& name) {
  PGconn* c = PQconnectdb((base + "/postgres").c_str());
  PQsetNoticeProcessor(
      c, [](void*, const char*) {}, nullptr);  // "does not exist, skipping"
  if (PQstatus(c) != CONNECTION_OK) {
    const std::string message = PQerrorMessage(c);
    PQfinish(c);
    throw std::runtime_error("test PostgreSQL at " + base + ": " + message);
  }
  // Two statements, two calls: CREATE DATABASE cannot run in the implicit transaction of one.
  for (const std::string& sql : {"DROP DATABASE IF EXISTS " + name, "CREATE DATABASE " + name}) {
    PGresult* r = PQexec(c, sql.c_str());
    const bool ok = PQresultStatus(r) == PGRES_COMMAND_OK;
    const std::string message = PQerrorMessage(c);
    PQclear(r);
    if (!ok) {
      PQfinish(c);
      throw std::runtime_error(sql + ": " + message);
    }
  }
  PQfinish(c);
}

}  // namespace

// The PostgreSQL build of the store tests is compiled with SALIENT_TEST_PG_DIR (the fixture's
// directory); SALIENT_TEST_BACKEND chooses for any other.
bool on_postgresql() {
  const std::string backend = env("SALIENT_TEST_BACKEND");
#ifdef SALIENT_TEST_PG_DIR
  return backend != "sqlite";
#else
  return backend == "postgresql";
#endif
}

server::DatabaseUrl test_database(const ScratchDir& scratch) {
  if (!on_postgresql()) return server::DatabaseUrl::sqlite(scratch.path / "salient.db");
  static std::map<std::string, server::DatabaseUrl> made;
  auto it = made.find(scratch.path.string());
  if (it != made.end()) return it->second;
  // One database per test: named by the process and a count, as scratch directories are.
  std::string name = "t";  // appended, not "t" + …: GCC 12 warns falsely (-Wrestrict) on that
  name += std::to_string(::getpid());
  name += '_';
  name += std::to_string(made.size());
  const std::string base = cluster_url();
  create_database(base, name);
  return made[scratch.path.string()] = server::DatabaseUrl{server::Dialect::postgresql, base + "/" + name};
}

}  // namespace salient::test
