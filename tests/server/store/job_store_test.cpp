#include "server/store/job_store.hpp"

#include <doctest/doctest.h>

#include <filesystem>
#include <set>

#include "tests/support/scratch_dir.hpp"
#include "tests/support/test_database.hpp"

namespace fs = std::filesystem;
using namespace salient::server;

TEST_CASE("jobs: created queued, started oldest first, finished once, listed newest first") {
  const salient::test::ScratchDir scratch("jobs");
  Database db(salient::test::test_database(scratch));
  JobStore jobs(db);
  const Job a = jobs.create("bunny.obj", "m1", "{}", "s1", 10);
  const Job b = jobs.create("spot.obj", "m2", "{}", "s1", 11);
  CHECK(a.id != b.id);
  CHECK(jobs.count(JobState::queued) == 2);
  auto started = jobs.claim("n1", 30, 12);
  REQUIRE(started);
  CHECK(started->id == a.id);
  CHECK(started->attempts == 1);
  CHECK(*started->node == "n1");
  CHECK(*started->lease_until == 42);
  jobs.set_progress(a.id, JobPhase::saliency, 0.25);
  CHECK(jobs.get(a.id)->phase == JobPhase::saliency);
  CHECK(jobs.finish(a.id, {"n1", 1}, JobState::done, std::nullopt, std::string(R"({"layers": 539})"), 13));
  CHECK_FALSE(jobs.finish(a.id, {"n1", 1}, JobState::failed, std::string("late"), std::nullopt,
                          14));  // already finished
  const Job done = *jobs.get(a.id);
  CHECK(done.state == JobState::done);
  CHECK(done.progress == 1);
  CHECK(*done.result == R"({"layers": 539})");
  CHECK(*done.finished_at == 13);
  const auto all = jobs.list(std::nullopt, 10, 0);
  REQUIRE(all.size() == 2);
  CHECK(all[0].id == b.id);
  CHECK(jobs.list(JobState::done, 10, 0).size() == 1);
  CHECK(jobs.list(std::nullopt, 1, 1)[0].id == a.id);  // paging
  CHECK(jobs.find_done("m1", "s1")->id == a.id);
  CHECK_FALSE(jobs.find_done("m2", "s1"));
  CHECK(jobs.remove(b.id));
  CHECK_FALSE(jobs.get(b.id));
}

TEST_CASE("jobs: a finished job has no phase, in its row and as read (older rows kept 'toolpaths')") {
  const salient::test::ScratchDir scratch("jobs");
  Database db(salient::test::test_database(scratch));
  JobStore jobs(db);
  const auto phase_in_row = [&](const std::string& id) {
    auto q = db.prepare("SELECT phase FROM jobs WHERE id = ?");
    q.bind(1, std::string_view(id));
    REQUIRE(q.step());
    return q.text(0);
  };
  for (JobState end : {JobState::done, JobState::failed, JobState::cancelled}) {
    const std::string id = jobs.create("bunny.obj", "m", "{}", "s", 1).id;
    REQUIRE(jobs.claim("n1", 30, 2));
    jobs.set_progress(id, JobPhase::toolpaths, 0.9);
    CHECK(jobs.get(id)->phase == JobPhase::toolpaths);
    REQUIRE(jobs.finish(id, {"n1", 1}, end, std::nullopt, std::nullopt, 3));
    CHECK_MESSAGE(jobs.get(id)->phase == JobPhase::none, std::string(to_string(end)));
    CHECK(phase_in_row(id).empty());
    // A row a previous version finished with its last phase still reads as none.
    db.prepare("UPDATE jobs SET phase = 'toolpaths' WHERE id = ?").bind(1, std::string_view(id)).run();
    CHECK(jobs.get(id)->phase == JobPhase::none);
  }
}

TEST_CASE("jobs: a restart puts running jobs back in the queue, with their attempts counted") {
  const salient::test::ScratchDir scratch("jobs");
  std::string id;
  {
    Database db(salient::test::test_database(scratch));
    JobStore jobs(db);
    id = jobs.create("bunny.obj", "m", "{}", "s", 1).id;
    jobs.claim("n1", 30, 2);
    jobs.set_progress(id, JobPhase::plan, 0.6);
  }  // the daemon dies here
  Database db(salient::test::test_database(scratch));
  JobStore jobs(db);
  CHECK(jobs.requeue_running("n2", 3).empty());  // another node's job: not ours to take
  CHECK(jobs.requeue_running("n1", 3).size() == 1);
  const Job j = *jobs.get(id);
  CHECK(j.state == JobState::queued);
  CHECK(j.progress == 0);
  CHECK_FALSE(j.node);
  CHECK(j.requeues.find("node n1 restarted") != std::string::npos);
  CHECK(jobs.claim("n1", 30, 3)->attempts == 2);
}

TEST_CASE("job states round-trip through their names") {
  for (JobState st :
       {JobState::queued, JobState::running, JobState::done, JobState::failed, JobState::cancelled})
    CHECK(job_state_from(to_string(st)) == st);
  CHECK_FALSE(job_state_from("exploded"));
}
