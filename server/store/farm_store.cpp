#include "server/store/farm_store.hpp"

namespace salient::server {
namespace {

// The heartbeat's age by the database's clock, as every node's heartbeat is written.
constexpr const char* printer_columns =
    "p.id, p.node, p.profile, p.status, p.updated_at, COALESCE(n.heartbeat_at, 0), "
    "{NOW} - COALESCE(n.heartbeat_at, 0) FROM farm_printers p LEFT JOIN nodes n ON n.id = p.node";

FarmPrinter read_printer(const Database::Statement& q) {
  return {q.text(0), q.text(1), q.text(2), q.text(3), q.real(4), q.real(5), q.real(6)};
}

constexpr const char* node_columns =
    "id, roles, version, started_at, heartbeat_at, {NOW} - heartbeat_at FROM nodes";

FarmNode read_node(const Database::Statement& q) {
  return {q.text(0), q.text(1), q.null(2) ? "" : q.text(2), q.null(3) ? 0 : q.real(3), q.real(4), q.real(5)};
}

}  // namespace

double FarmStore::clock() {
  auto q = db_.prepare(dialect_sql(db_, "SELECT {NOW}"));
  q.step();
  const double now = q.real(0);
  q.run();
  return now;
}

bool FarmStore::heartbeat(const FarmNode& node) {
  db_.prepare("UPDATE nodes SET roles = ?, version = ?, started_at = ?, heartbeat_at = ? WHERE id = ?")
      .bind(1, std::string_view(node.roles))
      .bind(2, std::string_view(node.version))
      .bind(3, node.started_at)
      .bind(4, node.heartbeat_at)
      .bind(5, std::string_view(node.id))
      .run();
  if (db_.changes() == 1) return false;
  // No row: a first start, or one forgotten (DELETE /api/v1/nodes/{id}) while the node was away.
  db_.prepare(
         "INSERT INTO nodes (id, roles, version, started_at, heartbeat_at) VALUES (?, ?, ?, ?, ?) "
         "ON CONFLICT (id) DO UPDATE SET roles = excluded.roles, version = excluded.version, "
         "started_at = excluded.started_at, heartbeat_at = excluded.heartbeat_at")
      .bind(1, std::string_view(node.id))
      .bind(2, std::string_view(node.roles))
      .bind(3, std::string_view(node.version))
      .bind(4, node.started_at)
      .bind(5, node.heartbeat_at)
      .run();
  return true;
}

std::optional<FarmNode> FarmStore::node(const std::string& id) {
  auto q = db_.prepare(dialect_sql(db_, std::string("SELECT ") + node_columns + " WHERE id = ?"));
  q.bind(1, std::string_view(id));
  if (!q.step()) return std::nullopt;
  FarmNode n = read_node(q);
  q.run();
  return n;
}

std::vector<FarmNode> FarmStore::nodes() {
  auto q = db_.prepare(dialect_sql(db_, std::string("SELECT ") + node_columns + " ORDER BY id"));
  std::vector<FarmNode> out;
  while (q.step()) out.push_back(read_node(q));
  return out;
}

FarmStore::Forget FarmStore::forget(const std::string& node, double lease_seconds) {
  Database::Transaction t(db_);  // a node that comes back meanwhile either is refused or stays
  // Locked on PostgreSQL, so that a heartbeat arriving now waits and then finds no row: it makes
  // a new one, and the node's printers register again at its next start.
  auto q = db_.prepare(dialect_sql(db_, std::string("SELECT ") + node_columns + " WHERE id = ?" +
                                            (db_.dialect() == Dialect::postgresql ? " FOR UPDATE" : "")));
  q.bind(1, std::string_view(node));
  if (!q.step()) return Forget::unknown;
  const FarmNode row = read_node(q);
  q.run();
  if (row.heartbeat_age <= lease_seconds) return Forget::alive;
  db_.prepare("UPDATE printer_requests SET state = 'cancelled' WHERE node = ? AND state = 'pending'")
      .bind(1, std::string_view(node))
      .run();
  db_.prepare("DELETE FROM farm_printers WHERE node = ?").bind(1, std::string_view(node)).run();
  db_.prepare("DELETE FROM nodes WHERE id = ?").bind(1, std::string_view(node)).run();
  t.commit();
  return Forget::forgotten;
}

void FarmStore::register_printers(const std::string& node, const std::vector<Registration>& printers,
                                  double now, double live_after) {
  Database::Transaction t(db_);  // two nodes starting at once: one registers, the other sees it
  std::vector<std::string> ids;
  for (const Registration& r : printers) ids.push_back(r.id);
  check_unclaimed(node, ids, live_after);
  db_.prepare("DELETE FROM farm_printers WHERE node = ?").bind(1, std::string_view(node)).run();
  auto insert = db_.prepare(
      "INSERT INTO farm_printers (id, node, profile, status, updated_at) VALUES (?, ?, ?, ?, ?) "
      "ON CONFLICT (id) DO UPDATE SET node = excluded.node, profile = excluded.profile, "
      "status = excluded.status, updated_at = excluded.updated_at");
  for (const Registration& r : printers)
    insert.bind(1, std::string_view(r.id))
        .bind(2, std::string_view(node))
        .bind(3, std::string_view(r.profile))
        .bind(4, std::string_view(r.status))
        .bind(5, now)
        .run();
  t.commit();
}

void FarmStore::check_unclaimed(const std::string& node, const std::vector<std::string>& printer_ids,
                                double live_after) {
  auto q = db_.prepare(
      "SELECT p.node FROM farm_printers p JOIN nodes n ON n.id = p.node "
      "WHERE p.id = ? AND p.node <> ? AND n.heartbeat_at >= ?");
  for (const std::string& id : printer_ids) {
    q.bind(1, std::string_view(id)).bind(2, std::string_view(node)).bind(3, live_after);
    if (!q.step()) continue;
    const std::string other = q.text(0);
    q.run();
    throw StoreError("printer id '" + id + "' is already registered by node '" + other +
                     "', which is live; node '" + node +
                     "' cannot register it too (printer ids are unique in the farm)");
  }
}

void FarmStore::set_status(const std::string& id, const std::string& node, const std::string& status,
                           double now) {
  db_.prepare("UPDATE farm_printers SET status = ?, updated_at = ? WHERE id = ? AND node = ?")
      .bind(1, std::string_view(status))
      .bind(2, now)
      .bind(3, std::string_view(id))
      .bind(4, std::string_view(node))
      .run();
}

std::vector<FarmPrinter> FarmStore::printers() {
  auto q = db_.prepare(dialect_sql(db_, std::string("SELECT ") + printer_columns + " ORDER BY p.id"));
  std::vector<FarmPrinter> out;
  while (q.step()) out.push_back(read_printer(q));
  return out;
}

std::optional<FarmPrinter> FarmStore::printer(const std::string& id) {
  auto q = db_.prepare(dialect_sql(db_, std::string("SELECT ") + printer_columns + " WHERE p.id = ?"));
  q.bind(1, std::string_view(id));
  if (!q.step()) return std::nullopt;
  FarmPrinter p = read_printer(q);
  q.run();
  return p;
}

bool FarmStore::profile_live(const std::string& profile, double live_after) {
  auto q = db_.prepare(
      "SELECT COUNT(*) FROM farm_printers p JOIN nodes n ON n.id = p.node "
      "WHERE p.profile = ? AND n.heartbeat_at >= ?");
  q.bind(1, std::string_view(profile)).bind(2, live_after);
  q.step();
  const bool live = q.integer(0) > 0;
  q.run();
  return live;
}

int FarmStore::interrupt_dead(const std::string& except_node, double live_after, double now) {
  db_.prepare(
         "UPDATE prints SET state = 'interrupted', finished_at = ?, "
         "reason = 'its node stopped answering during the print' "
         "WHERE finished_at IS NULL AND printer_id IN (SELECT p.id FROM farm_printers p "
         "JOIN nodes n ON n.id = p.node WHERE n.heartbeat_at < ? AND p.node <> ?)")
      .bind(1, now)
      .bind(2, live_after)
      .bind(3, std::string_view(except_node))
      .run();
  return db_.changes();
}

int FarmStore::interrupt_own(const std::vector<std::string>& printer_ids, double now) {
  int n = 0;
  auto q = db_.prepare(
      "UPDATE prints SET state = 'interrupted', reason = 'the daemon stopped during the print', "
      "finished_at = ? WHERE finished_at IS NULL AND printer_id = ?");
  for (const std::string& id : printer_ids) {
    q.bind(1, now).bind(2, std::string_view(id)).run();
    n += db_.changes();
  }
  return n;
}

long long FarmStore::post(const PrinterRequest& r, double now) {
  auto q = db_.prepare(
      "INSERT INTO printer_requests (node, state, method, target, body, caller, role, created_at) "
      "VALUES (?, 'pending', ?, ?, ?, ?, ?, ?) RETURNING id");
  q.bind(1, std::string_view(r.node))
      .bind(2, std::string_view(r.method))
      .bind(3, std::string_view(r.target))
      .bind(4, std::string_view(r.body))
      .bind(5, std::string_view(r.user))
      .bind(6, std::string_view(r.role))
      .bind(7, now);
  q.step();
  const long long id = q.integer(0);
  q.run();
  return id;
}

std::vector<PrinterRequest> FarmStore::take(const std::string& node, int limit) {
  std::vector<PrinterRequest> pending;
  {
    auto q = db_.prepare(
        "SELECT id, node, method, target, body, caller, role FROM printer_requests "
        "WHERE node = ? AND state = 'pending' ORDER BY id LIMIT ?");
    q.bind(1, std::string_view(node)).bind(2, static_cast<std::int64_t>(limit));
    while (q.step())
      pending.push_back({q.integer(0), q.text(1), q.text(2), q.text(3), q.text(4), q.text(5), q.text(6)});
  }
  std::vector<PrinterRequest> taken;
  auto claim = db_.prepare("UPDATE printer_requests SET state = 'taken' WHERE id = ? AND state = 'pending'");
  for (PrinterRequest& r : pending) {
    claim.bind(1, static_cast<std::int64_t>(r.id)).run();
    if (db_.changes() == 1) taken.push_back(std::move(r));  // else cancelled (or taken) meanwhile
  }
  return taken;
}

bool FarmStore::answer(long long id, const PrinterAnswer& a, double now) {
  db_.prepare(
         "UPDATE printer_requests SET state = 'answered', status = ?, headers = ?, response = ?, "
         "answered_at = ? WHERE id = ? AND state = 'taken'")
      .bind(1, static_cast<std::int64_t>(a.status))
      .bind(2, std::string_view(a.headers))
      .bind(3, std::string_view(a.body))
      .bind(4, now)
      .bind(5, static_cast<std::int64_t>(id))
      .run();
  return db_.changes() == 1;
}

std::optional<PrinterAnswer> FarmStore::answer_of(long long id) {
  auto q = db_.prepare(
      "SELECT status, headers, response FROM printer_requests WHERE id = ? AND state = 'answered'");
  q.bind(1, static_cast<std::int64_t>(id));
  if (!q.step()) return std::nullopt;
  PrinterAnswer a{static_cast<int>(q.integer(0)), q.null(1) ? "[]" : q.text(1), q.null(2) ? "" : q.text(2)};
  q.run();
  return a;
}

bool FarmStore::cancel(long long id) {
  // Only a pending one: a taken request is being run by its node, and a cancel cannot undo that.
  db_.prepare("UPDATE printer_requests SET state = 'cancelled' WHERE id = ? AND state = 'pending'")
      .bind(1, static_cast<std::int64_t>(id))
      .run();
  return db_.changes() == 1;
}

int FarmStore::purge(double before) {
  db_.prepare("DELETE FROM printer_requests WHERE state IN ('answered', 'cancelled') AND created_at < ?")
      .bind(1, before)
      .run();
  return db_.changes();
}

}  // namespace salient::server
