// claims_bench: how many job claims per second the store sustains with the lease scheme of
// jobs across nodes (JobStore::claim, renew, finish), i.e. the ceiling of slicers it can feed.
// K threads, each with its own connection and node id, repeatedly claim the oldest queued job,
// renew their lease and finish it (trivially small, pre-inserted jobs: only the store's work is
// measured). For each K, JOBS jobs are inserted, then claimed to the last; prints claims/s.
//   claims_bench DATABASE_URL [JOBS] [K…]     (default: 2000 jobs, K = 1 2 4 8)
// DATABASE_URL: postgresql://… (the benchmark makes a database of its own beside that one and drops
// it at the end: a daemon working on the named one would take its jobs) or a SQLite file.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <thread>
#include <vector>

#include "server/store/database.hpp"
#include "server/store/job_store.hpp"

using namespace salient::server;
using Clock = std::chrono::steady_clock;

namespace {

void insert_jobs(Database& db, int n) {
  db.exec("DELETE FROM jobs");
  Database::Transaction t(db);
  JobStore jobs(db);
  for (int i = 0; i < n; ++i) jobs.create("m.obj", std::to_string(i), "{}", "s", i);
  t.commit();
}

// One slicer's loop: claim → renew → finish until the queue is empty. Returns the claims made.
int slicer(const DatabaseUrl& url, int index) {
  Database db(url);
  JobStore jobs(db);
  std::string node = "bench-";
  node += std::to_string(index);
  int claims = 0;
  for (;;) {
    auto j = jobs.claim(node, 15);
    if (!j) {
      if (jobs.count(JobState::queued) == 0) return claims;
      continue;  // the rows left are being claimed by others
    }
    ++claims;
    jobs.renew(node, 15);
    if (!jobs.finish(j->id, {node, j->attempts}, JobState::done, std::nullopt, std::string("{}")))
      std::fprintf(stderr, "finish of %s refused\n", j->id.c_str());
  }
}

// The same server, another database: "postgresql://u@h:p/db?x" → "postgresql://u@h:p/NAME?x".
std::string with_database(const std::string& uri, const std::string& name) {
  const std::size_t query = uri.find('?');
  const std::string base = uri.substr(0, query), rest = query == std::string::npos ? "" : uri.substr(query);
  const std::size_t slash = base.find('/', base.find("://") + 3);
  return (slash == std::string::npos ? base : base.substr(0, slash)) + "/" + name + rest;
}

// For each K: JOBS jobs inserted, then K slicers claim them all. False if any job was not claimed
// and done exactly once.
bool measure(const DatabaseUrl& url, int n, const std::vector<int>& ks) {
  Database setup(url);
  std::printf("%s, %d jobs per run: claim + renew + finish per job\n",
              url.dialect == Dialect::postgresql ? "PostgreSQL" : "SQLite", n);
  std::printf("%8s %10s %12s %12s\n", "threads", "seconds", "claims/s", "ms/claim");
  for (int k : ks) {
    insert_jobs(setup, n);
    std::vector<std::thread> threads;
    std::vector<int> claims(static_cast<std::size_t>(k));
    const auto t0 = Clock::now();
    for (int i = 0; i < k; ++i)
      threads.emplace_back([&, i] { claims[static_cast<std::size_t>(i)] = slicer(url, i); });
    for (auto& t : threads) t.join();
    const double s = std::chrono::duration<double>(Clock::now() - t0).count();
    int total = 0;
    for (int c : claims) total += c;
    if (total != n || JobStore(setup).count(JobState::done) != n) {
      std::fprintf(stderr, "K=%d: %d claims for %d jobs\n", k, total, n);
      return false;
    }
    std::printf("%8d %10.2f %12.0f %12.3f\n", k, s, n / s, 1000.0 * s * k / n);
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) try {
  if (argc < 2) {
    std::fprintf(stderr, "usage: claims_bench DATABASE_URL [JOBS] [K...]\n");
    return 2;
  }
  const DatabaseUrl url = DatabaseUrl::parse(argv[1]);
  const int n = argc > 2 ? std::atoi(argv[2]) : 2000;
  std::vector<int> ks;
  for (int i = 3; i < argc; ++i) ks.push_back(std::atoi(argv[i]));
  if (ks.empty()) ks = {1, 2, 4, 8};
  if (url.dialect == Dialect::sqlite) return measure(url, n, ks) ? 0 : 1;
  std::string name = "claims_bench_";
  name += std::to_string(::getpid());
  Database admin(url);
  admin.exec("DROP DATABASE IF EXISTS " + name);
  admin.exec("CREATE DATABASE " + name);
  const bool ok = measure({Dialect::postgresql, with_database(url.target, name)}, n, ks);
  admin.exec("DROP DATABASE " + name);
  return ok ? 0 : 1;
} catch (const std::exception& e) {
  std::fprintf(stderr, "claims_bench: %s\n", e.what());
  return 1;
}
