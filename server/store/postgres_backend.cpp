// The PostgreSQL backend (libpq). Each statement is one round trip (a prepared statement's bind
// and execute; the prepare once per connection), where a SQLite step is none; results come in
// text format and are converted on reading. The schema version lives in a table, salient_schema; writers that
// SQLite would serialise with BEGIN IMMEDIATE are serialised here by a transaction-scoped advisory lock.
#include <libpq-fe.h>
#include <poll.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <unordered_map>
#include <vector>

#include "server/store/database_backend.hpp"
#include "server/store/file_store.hpp"  // StoreError

namespace salient::server::detail {
namespace {

// Type OIDs of the parameters we send (pg_type.h): the server then needs no guessing, as in
// "length($1)" where text and bytea would both fit.
constexpr Oid int8_oid = 20, text_oid = 25, float8_oid = 701, bytea_oid = 17;
// The advisory lock all write transactions take ('salient' in ASCII), and the one start-up takes.
constexpr const char* write_lock = "SELECT pg_advisory_xact_lock(32199672297647732)";

struct ResultDeleter {
  void operator()(PGresult* r) const { PQclear(r); }
};
using Result = std::unique_ptr<PGresult, ResultDeleter>;

[[noreturn]] void fail(PGconn* conn, const PGresult* r, std::string_view what) {
  const char* state = r ? PQresultErrorField(r, PG_DIAG_SQLSTATE) : nullptr;
  std::string message = r ? PQresultErrorMessage(r) : PQerrorMessage(conn);
  while (!message.empty() && (message.back() == '\n' || message.back() == ' ')) message.pop_back();
  // 53100 disk_full, 53200 out_of_memory…: class 53 is "insufficient resources".
  const bool full = state && std::strcmp(state, "53100") == 0;
  throw StoreError(std::string(what) + message, full);
}

// "?" and "?N" (SQLite's) become "$N" (PostgreSQL's); a bare "?" takes the next number after the
// largest so far, as in SQLite. Quoted strings and identifiers are left alone.
std::string translate_placeholders(std::string_view sql, int& count) {
  std::string out;
  out.reserve(sql.size() + 8);
  count = 0;
  for (std::size_t i = 0; i < sql.size(); ++i) {
    const char c = sql[i];
    if (c == '\'' || c == '"') {
      const std::size_t end = sql.find(c, i + 1);
      const std::size_t stop = end == std::string_view::npos ? sql.size() : end + 1;
      out.append(sql.substr(i, stop - i));
      i = stop - 1;
      continue;
    }
    if (c != '?') {
      out += c;
      continue;
    }
    std::size_t j = i + 1;
    int n = 0;
    while (j < sql.size() && sql[j] >= '0' && sql[j] <= '9') n = n * 10 + (sql[j++] - '0');
    if (j == i + 1) n = count + 1;
    count = std::max(count, n);
    out += '$' + std::to_string(n);
    i = j - 1;
  }
  return out;
}

int hex_value(char c) {
  return c <= '9' ? c - '0' : (c | 0x20) - 'a' + 10;
}

// One connection and what lives with it: the statements it has prepared (each SQL text, with its
// parameter types, is parsed and planned once per connection; later runs send only the values, in
// the same one round trip), and the rows the last write touched.
struct Connection {
  PGconn* conn = nullptr;
  int changes = 0;
  std::unordered_map<std::string, std::string> prepared;  // SQL and parameter types → name
  bool said_fatal = false;  // the server sent a FATAL error while idle: its session has ended

  // Installed once: PQreset keeps it.
  static void receive_notice(void* self, const PGresult* r) {
    const char* severity = PQresultErrorField(r, PG_DIAG_SEVERITY_NONLOCALIZED);
    if (severity && (std::strcmp(severity, "FATAL") == 0 || std::strcmp(severity, "PANIC") == 0))
      static_cast<Connection*>(self)->said_fatal = true;
  }

  void note_changes(const PGresult* r) {
    const char* status = PQcmdStatus(const_cast<PGresult*>(r));
    if (std::strncmp(status, "INSERT", 6) == 0 || std::strncmp(status, "UPDATE", 6) == 0 ||
        std::strncmp(status, "DELETE", 6) == 0)
      changes = std::atoi(PQcmdTuples(const_cast<PGresult*>(r)));
  }

  // After a failure: a connection that broke (a restarted server, a terminated backend) is
  // reconnected for the next statement. The failed one is not run again: it may have committed.
  Result checked(PGresult* raw, std::string_view what) {
    Result r(raw);
    const ExecStatusType status = r ? PQresultStatus(r.get()) : PGRES_FATAL_ERROR;
    if (status == PGRES_COMMAND_OK || status == PGRES_TUPLES_OK) return r;
    if (PQstatus(conn) == CONNECTION_BAD) {
      prepared.clear();  // they went with the old session
      said_fatal = false;
      PQreset(conn);
    }
    fail(conn, r.get(), what);
  }

  // Before a statement: a connection the server closed while it was idle (a restart, a terminated
  // backend: its socket then reads the goodbye or EOF) is opened again now, before anything is
  // sent, so the statement runs instead of failing (each HTTP thread's next request failed 500
  // after a restart). Not inside a transaction: that went with the old session, and must fail.
  void revive() {
    const PGTransactionStatusType t = PQtransactionStatus(conn);
    if (t == PQTRANS_INTRANS || t == PQTRANS_INERROR || t == PQTRANS_ACTIVE) return;
    // A terminated backend sends its FATAL message, then closes: libpq, idle, passes the message
    // to the notice receiver (said_fatal) and keeps the connection OK until it reads the end,
    // which may come a moment later. Either tells the session is over.
    for (int reads = 0; PQstatus(conn) == CONNECTION_OK; ++reads) {
      pollfd p{PQsocket(conn), POLLIN, 0};
      if (p.fd < 0 || ::poll(&p, 1, 0) <= 0 || reads == 4) break;
      if (PQconsumeInput(conn) == 0) break;
      PQisBusy(conn);  // parses what was read: a FATAL message reaches the notice receiver
    }
    if (PQstatus(conn) == CONNECTION_OK && !said_fatal) return;  // as it was
    said_fatal = false;
    prepared.clear();  // they went with the old session
    PQreset(conn);
  }

  Result execute(const std::string& sql, int n, const Oid* types, const char* const* values,
                 const int* lengths, const int* formats) {
    revive();
    std::string key = sql;
    key.append(reinterpret_cast<const char*>(types), sizeof(Oid) * static_cast<std::size_t>(n));
    auto it = prepared.find(key);
    if (it == prepared.end()) {
      std::string name = "s";  // appended: GCC 12 warns falsely (-Wrestrict) on "s" + …
      name += std::to_string(prepared.size());
      checked(PQprepare(conn, name.c_str(), sql.c_str(), n, types), "PostgreSQL: ");
      it = prepared.emplace(std::move(key), std::move(name)).first;
    }
    return checked(PQexecPrepared(conn, it->second.c_str(), n, values, lengths, formats, 0), "PostgreSQL: ");
  }
};

class PostgresStatement final : public StatementBackend {
 public:
  PostgresStatement(Connection& c, std::string_view sql) : c_(c), head_(sql.substr(0, 60)) {
    int count = 0;
    sql_ = translate_placeholders(sql, count);
    params_.resize(static_cast<std::size_t>(count));
  }

  void bind_integer(int i, std::int64_t v) override { slot(i) = {std::to_string(v), int8_oid, false, false}; }
  void bind_real(int i, double v) override {
    char text[32];
    std::snprintf(text, sizeof text, "%.17g", v);
    slot(i) = {text, float8_oid, false, false};
  }
  void bind_text(int i, std::string_view t) override { slot(i) = {std::string(t), text_oid, false, false}; }
  void bind_blob(int i, std::string_view b) override { slot(i) = {std::string(b), bytea_oid, true, false}; }
  void bind_null(int i) override { slot(i) = {{}, 0, false, true}; }

  bool step() override {
    if (!result_) {
      run();
      row_ = -1;
    }
    if (++row_ < PQntuples(result_.get())) return true;
    result_.reset();  // reset: the next step runs the statement again
    return false;
  }

  std::int64_t integer(int c) const override {
    const char* v = value(c);
    if (v[0] == 't' || v[0] == 'f') return v[0] == 't';  // a boolean ("x IS NULL"), 1 or 0 as in SQLite
    char* end = nullptr;
    const long long n = std::strtoll(v, &end, 10);
    return *end == '\0' ? n : static_cast<std::int64_t>(std::strtod(v, nullptr));  // a REAL read as integer
  }
  double real(int c) const override { return std::strtod(value(c), nullptr); }
  std::string text(int c) const override {
    return std::string(value(c), static_cast<std::size_t>(PQgetlength(result_.get(), row_, c)));
  }
  // bytea in text format is "\x" and two hex digits a byte.
  std::string blob(int c) const override {
    const char* v = value(c);
    const std::size_t n = static_cast<std::size_t>(PQgetlength(result_.get(), row_, c));
    if (n < 2 || v[0] != '\\' || v[1] != 'x') return std::string(v, n);
    std::string out((n - 2) / 2, '\0');
    for (std::size_t k = 0; k < out.size(); ++k)
      out[k] = static_cast<char>(hex_value(v[2 + 2 * k]) << 4 | hex_value(v[3 + 2 * k]));
    return out;
  }
  bool null(int c) const override { return PQgetisnull(result_.get(), row_, c) != 0; }

 private:
  struct Param {
    std::string value;
    Oid type = 0;
    bool binary = false;
    bool is_null = true;
  };
  Param& slot(int i) {
    if (i < 1 || i > static_cast<int>(params_.size()))
      throw StoreError("bind: parameter " + std::to_string(i) + " out of range in \"" + head_ + "\"");
    result_.reset();
    return params_[static_cast<std::size_t>(i - 1)];
  }
  const char* value(int c) const {
    if (!result_ || row_ < 0 || c < 0 || c >= PQnfields(result_.get())) return "";
    return PQgetvalue(result_.get(), row_, c);
  }
  void run() {
    const std::size_t n = params_.size();
    std::vector<Oid> types(n);
    std::vector<const char*> values(n);
    std::vector<int> lengths(n), formats(n);
    for (std::size_t k = 0; k < n; ++k) {
      types[k] = params_[k].type;
      values[k] = params_[k].is_null ? nullptr : params_[k].value.data();
      lengths[k] = static_cast<int>(params_[k].value.size());
      formats[k] = params_[k].binary ? 1 : 0;
    }
    result_ =
        c_.execute(sql_, static_cast<int>(n), types.data(), values.data(), lengths.data(), formats.data());
    c_.note_changes(result_.get());
  }

  Connection& c_;
  std::string head_, sql_;
  std::vector<Param> params_;
  Result result_;
  int row_ = -1;
};

class PostgresBackend final : public DatabaseBackend {
 public:
  explicit PostgresBackend(const std::string& url) {
    c_.conn = PQconnectdb(url.c_str());
    if (!c_.conn || PQstatus(c_.conn) != CONNECTION_OK) {
      std::string message = c_.conn ? PQerrorMessage(c_.conn) : "out of memory";
      while (!message.empty() && message.back() == '\n') message.pop_back();
      PQfinish(c_.conn);
      throw StoreError("PostgreSQL: cannot connect: " + message);
    }
    // Notices (e.g. "relation already exists, skipping") are not errors: keep them off stderr.
    PQsetNoticeReceiver(c_.conn, &Connection::receive_notice, &c_);
    // The tables of the backend itself, once per database; the lock orders two nodes starting
    // together. One round trip.
    try {
      exec(std::string("BEGIN; ") + write_lock +
           "; CREATE TABLE IF NOT EXISTS salient_schema (version BIGINT NOT NULL);"
           " INSERT INTO salient_schema SELECT 0 WHERE NOT EXISTS (SELECT 1 FROM salient_schema);"
           " CREATE TABLE IF NOT EXISTS blobs (digest TEXT NOT NULL, chunk_no BIGINT NOT NULL,"
           " data BYTEA NOT NULL, PRIMARY KEY (digest, chunk_no)); COMMIT");
    } catch (...) {
      PQfinish(c_.conn);
      throw;
    }
  }
  ~PostgresBackend() override { PQfinish(c_.conn); }

  Dialect dialect() const override { return Dialect::postgresql; }

  std::unique_ptr<StatementBackend> prepare(std::string_view sql) override {
    return std::make_unique<PostgresStatement>(c_, sql);
  }

  void exec(std::string_view sql) override {
    c_.revive();
    Result r = c_.checked(PQexec(c_.conn, std::string(sql).c_str()), "PostgreSQL: ");
    c_.note_changes(r.get());
    // A failed statement inside a transaction block leaves it aborted: ROLLBACK is what follows.
  }

  // Without RETURNING: the value the last INSERT took from a sequence in this session.
  std::int64_t last_insert_id() override {
    auto q = prepare("SELECT lastval()");
    return q->step() ? q->integer(0) : 0;
  }
  int changes() const override { return c_.changes; }
  bool in_transaction() const override { return PQtransactionStatus(c_.conn) != PQTRANS_IDLE; }

  int schema_version() override {
    auto q = prepare("SELECT version FROM salient_schema");
    return q->step() ? static_cast<int>(q->integer(0)) : 0;
  }
  void set_schema_version(int version) override {
    exec("UPDATE salient_schema SET version = " + std::to_string(version));
  }
  void begin_write() override { exec(std::string("BEGIN; ") + write_lock); }

  // pg_notify rather than NOTIFY: the channel and payload are parameters, never quoted by hand.
  void notify(std::string_view channel, std::string_view payload) override {
    PostgresStatement q(c_, "SELECT pg_notify(?, ?)");
    q.bind_text(1, channel);
    q.bind_text(2, payload);
    while (q.step()) {
    }
  }
  void listen(std::string_view channel) override {
    // The channel was checked by Database (letters, digits, '_'): safe inside quotes.
    exec("LISTEN \"" + std::string(channel) + "\"");
  }
  std::optional<std::pair<std::string, std::string>> wait_notification(int timeout_ms) override;

 private:
  Connection c_;
};

// Notifications arrive on the socket between queries: read what is there, else poll() it until
// something comes. EOF or an error on the socket is a broken connection, reported as StoreError.
std::optional<std::pair<std::string, std::string>> PostgresBackend::wait_notification(int timeout_ms) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  for (;;) {
    if (PQconsumeInput(c_.conn) == 0 || PQstatus(c_.conn) == CONNECTION_BAD) {
      std::string message = PQerrorMessage(c_.conn);
      while (!message.empty() && (message.back() == '\n' || message.back() == ' ')) message.pop_back();
      throw StoreError("PostgreSQL: the listening connection was lost: " + message);
    }
    if (PGnotify* n = PQnotifies(c_.conn)) {
      std::pair<std::string, std::string> out(n->relname, n->extra ? n->extra : "");
      PQfreemem(n);
      return out;
    }
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) return std::nullopt;
    pollfd p{PQsocket(c_.conn), POLLIN, 0};
    if (p.fd < 0) throw StoreError("PostgreSQL: the listening connection has no socket");
    const int rc = ::poll(&p, 1, static_cast<int>(left.count()));
    if (rc < 0 && errno != EINTR) throw StoreError(std::string("PostgreSQL: poll: ") + std::strerror(errno));
  }
}

}  // namespace

std::unique_ptr<DatabaseBackend> open_postgresql(const std::string& url) {
  return std::make_unique<PostgresBackend>(url);
}

}  // namespace salient::server::detail
