// LivenessWitness: whether this node may call another node dead now. Heartbeats are judged on
// the database's clock, but a node that could not reach the database (PostgreSQL frozen, or this
// process paused) saw nobody beat meanwhile, and those nodes were as stuck as it was: after such
// a gap it waits a whole lease of working contact before it judges, so that they beat again first
// (a 21 s freeze had other nodes call a running print "interrupted"). Times are steady seconds.
#pragma once

#include <optional>

namespace salient::server {

class LivenessWitness {
 public:
  // `max_gap`: the longest pause between two rounds that still counts as unbroken contact.
  LivenessWitness(double lease_seconds, double max_gap_seconds)
      : lease_(lease_seconds), max_gap_(max_gap_seconds) {}

  // Started at `now` with contact (the first heartbeat written): judges at once, as a node that
  // starts must to take over a dead one's prints.
  void start(double now) { last_ = now, since_ = now - lease_; }
  // A round that reached the database, ending at `now`.
  void reached(double now) {
    if (!last_ || now - *last_ > max_gap_) since_ = now;
    last_ = now;
  }
  // A round that did not (the database away): contact is broken.
  void failed() { last_.reset(), since_.reset(); }
  bool may_judge(double now) const { return since_ && now - *since_ >= lease_; }

 private:
  double lease_, max_gap_;
  std::optional<double> last_, since_;  // the last round that reached it; unbroken since
};

}  // namespace salient::server
