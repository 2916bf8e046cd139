// When a node may call others dead (issue 32 item 15): not right after its own contact with the
// database broke (a PostgreSQL freeze, this node paused), only after a whole lease of contact.
#include "server/printers/liveness_witness.hpp"

#include <doctest/doctest.h>

using salient::server::LivenessWitness;

TEST_CASE("a node that started judges at once, and goes on while its rounds keep coming") {
  LivenessWitness w(15, 5);
  w.start(100);
  CHECK(w.may_judge(100));
  for (double t = 100.25; t < 200; t += 0.25) {
    w.reached(t);
    CHECK(w.may_judge(t));
  }
}

TEST_CASE("after a 21 s freeze it waits a lease of rounds before judging: the others beat again first") {
  LivenessWitness w(15, 5);
  w.start(0);
  for (double t = 0.25; t <= 10; t += 0.25) w.reached(t);
  w.reached(31);  // the round that hung on the frozen database ends
  CHECK_FALSE(w.may_judge(31));
  double t = 31;
  for (; t < 45.9; t += 0.25) {
    w.reached(t);
    CHECK_FALSE(w.may_judge(t));
  }
  for (; t < 47; t += 0.25) w.reached(t);
  CHECK(w.may_judge(t));
}

TEST_CASE("a failed round breaks contact too, and a gap of less than a beat does not") {
  LivenessWitness w(15, 5);
  w.start(0);
  w.reached(4.9);  // a slow round, under the beat
  CHECK(w.may_judge(4.9));
  w.failed();  // the database away
  CHECK_FALSE(w.may_judge(5));
  w.reached(6);
  CHECK_FALSE(w.may_judge(20));
  w.reached(21);
  CHECK_FALSE(w.may_judge(21));  // 21 - 6 = 15, but the gap 6 → 21 broke it again
  for (double t = 21.25; t <= 36.5; t += 0.25) w.reached(t);
  CHECK(w.may_judge(36.5));
}
