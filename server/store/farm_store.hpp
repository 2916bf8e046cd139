// FarmStore: what the nodes of a farm (several salientd on one PostgreSQL) know of each other:
// the nodes and their heartbeats (table nodes), every node's printers with their last status
// (farm_printers), and requests for a printer carried to the node that owns it
// (printer_requests). A node is live while its heartbeat is younger than the lease. Times are
// seconds since the epoch; the callers take heartbeats and liveness limits from clock(), the
// database's, so that hosts whose clocks disagree still agree on who is alive.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "server/store/database.hpp"

namespace salient::server {

struct FarmNode {
  std::string id, roles, version;
  double started_at = 0, heartbeat_at = 0;
  double heartbeat_age = 0;  // by the database's clock (read back; not written)
};

struct FarmPrinter {
  std::string id, node, profile;
  std::string status;  // the JSON document GET /api/v1/printers/{id} gives, as the node last wrote it
  double updated_at = 0;
  double heartbeat_at = 0;   // its node's (0: the node has no row)
  double heartbeat_age = 0;  // how long ago, by the database's clock
};

// A request for a printer, as the API node that received it wrote it.
struct PrinterRequest {
  long long id = 0;
  std::string node, method, target, body, user, role;
};

struct PrinterAnswer {
  int status = 0;
  std::string headers;  // JSON [[name, value], …]
  std::string body;
};

class FarmStore {
 public:
  explicit FarmStore(Database& db) : db_(db) {}

  double clock();  // the database's: seconds since the epoch
  // Renews the node's row; true when there was none and it was made (a first start, or the node
  // was forgotten while it was away: its printers must register again).
  bool heartbeat(const FarmNode& node);
  std::optional<FarmNode> node(const std::string& id);
  std::vector<FarmNode> nodes();
  // Forgets a retired node: its row and its printers' (their prints stay in the history), its
  // requests not yet taken cancelled. Only a node dead on the database's clock (no heartbeat for
  // `lease_seconds`); a live one is refused.
  enum class Forget { forgotten, unknown, alive };
  Forget forget(const std::string& node, double lease_seconds);
  // Registers `node`'s printers (id, profile, status), dropping its rows for printers it no
  // longer has, in one transaction. A printer id another live node holds (heartbeat after
  // `live_after`) is refused: StoreError naming both nodes.
  struct Registration {
    std::string id, profile, status;
  };
  void register_printers(const std::string& node, const std::vector<Registration>& printers, double now,
                         double live_after);
  // The same refusal, without registering (before a node touches anything of its printers).
  void check_unclaimed(const std::string& node, const std::vector<std::string>& printer_ids,
                       double live_after);
  void set_status(const std::string& id, const std::string& node, const std::string& status, double now);
  std::vector<FarmPrinter> printers();  // by id
  std::optional<FarmPrinter> printer(const std::string& id);
  // Whether a printer of `profile` is on a node live after `live_after`.
  bool profile_live(const std::string& profile, double live_after);

  // The running prints (printing, paused) of printers whose node's heartbeat is older than
  // `live_after` become interrupted, resumable from their last acknowledged command. Idempotent;
  // returns how many. `except_node`: the caller's own (its prints run, whatever its heartbeat says).
  int interrupt_dead(const std::string& except_node, double live_after, double now);
  // At a node's start: the unfinished prints of its own printers only (another node's go on).
  int interrupt_own(const std::vector<std::string>& printer_ids, double now);

  // Requests. post: pending, for `node`; take: the node's pending requests, each taken (pending →
  // taken) by one UPDATE checked with changes(), so that none runs twice; answer: only a taken
  // one (a cancelled request's answer is dropped); cancel: the caller gave up — a pending request
  // then never runs; false for one already taken (its node runs it: only its answer can tell).
  // answer_of: the answer once there.
  long long post(const PrinterRequest& request, double now);
  std::vector<PrinterRequest> take(const std::string& node, int limit);
  bool answer(long long id, const PrinterAnswer& answer, double now);
  std::optional<PrinterAnswer> answer_of(long long id);
  bool cancel(long long id);
  int purge(double before);  // ended requests older than `before`; returns how many

 private:
  Database& db_;
};

}  // namespace salient::server
