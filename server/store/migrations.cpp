#include "server/store/migrations.hpp"

#include <array>
#include <string_view>
#include <utility>
#include <vector>

namespace salient::server {
namespace {

const std::vector<const char*> migrations = {
    R"sql(
CREATE TABLE jobs (
  id TEXT PRIMARY KEY,
  state TEXT NOT NULL CHECK (state IN ('queued', 'running', 'done', 'failed', 'cancelled')),
  phase TEXT,
  progress {REAL} NOT NULL DEFAULT 0,
  filename TEXT NOT NULL,
  model_digest TEXT NOT NULL,
  settings TEXT NOT NULL,
  settings_digest TEXT NOT NULL,
  error TEXT,
  result TEXT,
  attempts {INT} NOT NULL DEFAULT 0,
  created_at {REAL} NOT NULL,
  started_at {REAL},
  finished_at {REAL}{JOBS_ROWID}
);
CREATE INDEX jobs_by_state ON jobs (state, created_at);
CREATE INDEX jobs_by_content ON jobs (model_digest, settings_digest, state);
CREATE TABLE printers (
  id TEXT PRIMARY KEY,
  config TEXT NOT NULL,
  updated_at {REAL} NOT NULL
);
CREATE TABLE prints (
  id {ID},
  printer_id TEXT NOT NULL,
  job_id TEXT REFERENCES jobs (id) ON DELETE SET NULL,
  file_digest TEXT NOT NULL,
  filename TEXT NOT NULL,
  state TEXT NOT NULL,
  confirmed {INT} NOT NULL DEFAULT 0,
  total {INT} NOT NULL,
  reason TEXT,
  started_at {REAL} NOT NULL,
  finished_at {REAL}
);
CREATE INDEX prints_by_printer ON prints (printer_id, started_at);
CREATE TABLE api_keys (
  id {ID},
  key_digest TEXT NOT NULL UNIQUE,
  label TEXT NOT NULL,
  created_at {REAL} NOT NULL
);
)sql",
    // 2: files uploaded to print (OctoPrint's /api/files/local), by name.
    R"sql(
CREATE TABLE files (
  name TEXT PRIMARY KEY,
  digest TEXT NOT NULL,
  size {INT} NOT NULL,
  uploaded_at {REAL} NOT NULL
);
)sql",
    // 3: each printer's print queue: requests that found the printer busy, waiting their turn.
    R"sql(
CREATE TABLE print_queue (
  id {ID},
  printer_id TEXT NOT NULL,
  kind TEXT NOT NULL CHECK (kind IN ('job', 'file')),
  ref TEXT NOT NULL,
  position {INT} NOT NULL,
  created_at {REAL} NOT NULL
);
CREATE INDEX print_queue_by_printer ON print_queue (printer_id, position);
)sql",
    // 4: users with roles; every key belongs to one. The keys made before (hex, the first
    // start's) belong to the user 'admin', who is an admin.
    R"sql(
CREATE TABLE users (
  name TEXT PRIMARY KEY,
  role TEXT NOT NULL CHECK (role IN ('admin', 'operator', 'viewer')),
  created_at {REAL} NOT NULL
);
INSERT INTO users (name, role, created_at)
  VALUES ('admin', 'admin', COALESCE((SELECT MIN(created_at) FROM api_keys), {NOW}));
ALTER TABLE api_keys ADD COLUMN {USER} TEXT NOT NULL DEFAULT 'admin';
CREATE INDEX api_keys_by_user ON api_keys ({USER});
)sql",
    // 5: folders of uploaded files (files.name is a path "a/b/c.gcode" inside them), and the
    // settings OctoPrint clients write (POST /api/settings), by key.
    R"sql(
CREATE TABLE folders (
  path TEXT PRIMARY KEY,
  created_at {REAL} NOT NULL
);
CREATE TABLE settings (
  key TEXT PRIMARY KEY,
  value TEXT NOT NULL,
  updated_at {REAL} NOT NULL
);
)sql",
    // 6: what each print used, for the history and its totals (Moonraker's filament_used and
    // print_duration): filament pushed up to the last confirmed command, and time spent paused.
    R"sql(
ALTER TABLE prints ADD COLUMN filament_mm {REAL} NOT NULL DEFAULT 0;
ALTER TABLE prints ADD COLUMN paused_seconds {REAL} NOT NULL DEFAULT 0;
)sql",
    // 7: jobs across nodes: the node holding a running job's claim and until when (a lease it
    // renews; the database's clock), a cancel asked from another node, and why the job went back
    // to the queue each time (a JSON array of {node, at, reason}).
    R"sql(
ALTER TABLE jobs ADD COLUMN node TEXT;
ALTER TABLE jobs ADD COLUMN lease_until {REAL};
ALTER TABLE jobs ADD COLUMN cancel_requested {INT} NOT NULL DEFAULT 0;
ALTER TABLE jobs ADD COLUMN requeues TEXT NOT NULL DEFAULT '[]';
CREATE INDEX jobs_by_node ON jobs (node, state);
)sql",
    // 8: printers across nodes (a farm on one PostgreSQL): the nodes and their liveness (a node
    // renews heartbeat_at; one older than its lease is dead), every node's printers with the
    // status GET /api/v1/printers/{id} gives, and requests for a printer carried to the node that
    // owns it (state: pending → taken → answered, or cancelled when the caller gave up).
    R"sql(
CREATE TABLE nodes (
  id TEXT PRIMARY KEY,
  roles TEXT NOT NULL,
  version TEXT,
  started_at {REAL},
  heartbeat_at {REAL} NOT NULL
);
CREATE TABLE farm_printers (
  id TEXT PRIMARY KEY,
  node TEXT NOT NULL,
  profile TEXT NOT NULL,
  status TEXT NOT NULL,
  updated_at {REAL} NOT NULL
);
CREATE INDEX farm_printers_by_node ON farm_printers (node);
CREATE TABLE printer_requests (
  id {ID},
  node TEXT NOT NULL,
  state TEXT NOT NULL CHECK (state IN ('pending', 'taken', 'answered', 'cancelled')),
  method TEXT NOT NULL,
  target TEXT NOT NULL,
  body TEXT NOT NULL,
  caller TEXT NOT NULL,
  role TEXT NOT NULL,
  status {INT},
  headers TEXT,
  response TEXT,
  created_at {REAL} NOT NULL,
  answered_at {REAL}
);
CREATE INDEX printer_requests_by_node ON printer_requests (node, state, id);
)sql",
    // 9: events too large for a NOTIFY payload (8000 bytes), which then carries the row's id
    // (server/events/event_relay). Rows are read once by each node and swept after minutes.
    R"sql(
CREATE TABLE event_payloads (
  id {ID},
  body TEXT NOT NULL,
  created_at {REAL} NOT NULL
);
CREATE INDEX event_payloads_by_age ON event_payloads (created_at);
)sql",
    // 10: what OctoPrint keeps in memory, here shared by a farm's nodes so that an app pairs, and a
    // push socket authenticates, through any of them: login sessions and app-key requests. Their
    // secrets (a session, an app's polling token) are kept as SHA-256 digests, as keys are; the
    // user token is what an admin is shown to decide by.
    R"sql(
CREATE TABLE sessions (
  session_digest TEXT PRIMARY KEY,
  user_name TEXT NOT NULL,
  key_id {INT} NOT NULL DEFAULT 0,
  created_at {REAL} NOT NULL
);
CREATE INDEX sessions_by_age ON sessions (created_at);
CREATE TABLE app_key_requests (
  app_token_digest TEXT PRIMARY KEY,
  user_token TEXT NOT NULL UNIQUE,
  app TEXT NOT NULL,
  user_name TEXT NOT NULL,
  remote TEXT NOT NULL,
  created_at {REAL} NOT NULL,
  polled_at {REAL} NOT NULL,
  decided {INT} NOT NULL DEFAULT 0,
  key_user TEXT,
  key_role TEXT
);
)sql",
};

// Token, SQLite's words, PostgreSQL's words. SQLite's are the text the entries had before there
// were two dialects, so that SQLite databases are made exactly as before.
constexpr std::array<std::array<std::string_view, 3>, 6> words = {{
    {"{ID}", "INTEGER PRIMARY KEY AUTOINCREMENT", "BIGINT GENERATED BY DEFAULT AS IDENTITY PRIMARY KEY"},
    {"{INT}", "INTEGER", "BIGINT"},
    {"{REAL}", "REAL", "DOUBLE PRECISION"},
    {"{NOW}", "CAST(strftime('%s', 'now') AS REAL)", "CAST(EXTRACT(EPOCH FROM now()) AS DOUBLE PRECISION)"},
    {"{USER}", "user", "\"user\""},
    {"{JOBS_ROWID}", "", ",\n  rowid BIGINT GENERATED ALWAYS AS IDENTITY"},
}};

}  // namespace

int migration_count() {
  return static_cast<int>(migrations.size());
}

std::string migration_sql(int index, Dialect dialect) {
  std::string sql = migrations.at(static_cast<std::size_t>(index));
  const std::size_t column = dialect == Dialect::sqlite ? 1 : 2;
  for (const auto& w : words)
    for (std::size_t at = sql.find(w[0]); at != std::string::npos; at = sql.find(w[0], at + w[column].size()))
      sql.replace(at, w[0].size(), w[column]);
  return sql;
}

}  // namespace salient::server
