#include "server/store/database.hpp"

#include <algorithm>

#include "server/store/database_backend.hpp"
#include "server/store/migrations.hpp"

namespace salient::server {

Database::Statement::Statement(std::unique_ptr<detail::StatementBackend> impl) : impl_(std::move(impl)) {}
Database::Statement::Statement(Statement&&) noexcept = default;
Database::Statement::~Statement() = default;

Database::Statement& Database::Statement::bind(int i, std::int64_t v) {
  impl_->bind_integer(i, v);
  return *this;
}
Database::Statement& Database::Statement::bind(int i, double v) {
  impl_->bind_real(i, v);
  return *this;
}
Database::Statement& Database::Statement::bind(int i, std::string_view t) {
  impl_->bind_text(i, t);
  return *this;
}
Database::Statement& Database::Statement::bind_blob(int i, std::string_view b) {
  impl_->bind_blob(i, b);
  return *this;
}
Database::Statement& Database::Statement::bind_null(int i) {
  impl_->bind_null(i);
  return *this;
}
Database::Statement& Database::Statement::bind(int i, const std::optional<std::string>& t) {
  return t ? bind(i, std::string_view(*t)) : bind_null(i);
}

bool Database::Statement::step() {
  return impl_->step();
}
void Database::Statement::run() {
  while (step()) {
  }
}
std::int64_t Database::Statement::integer(int c) const {
  return impl_->integer(c);
}
double Database::Statement::real(int c) const {
  return impl_->real(c);
}
bool Database::Statement::null(int c) const {
  return impl_->null(c);
}
std::string Database::Statement::text(int c) const {
  return impl_->text(c);
}
std::string Database::Statement::blob(int c) const {
  return impl_->blob(c);
}

Database::Database(const DatabaseUrl& url)
    : backend_(url.dialect == Dialect::sqlite ? detail::open_sqlite(url.target)
                                              : detail::open_postgresql(url.target)) {
  migrate();
}

Database::Database(const std::filesystem::path& file) : Database(DatabaseUrl::sqlite(file)) {}

Database::~Database() = default;

std::string dialect_sql(const Database& db, std::string sql) {
  const bool pg = db.dialect() == Dialect::postgresql;
  const std::pair<std::string_view, std::string_view> words[] = {
      {"{NOW}", pg ? "CAST(EXTRACT(EPOCH FROM clock_timestamp()) AS DOUBLE PRECISION)"
                   : "((julianday('now') - 2440587.5) * 86400.0)"},
      {"{REAL}", pg ? "DOUBLE PRECISION" : "REAL"},
      {"{SKIP_LOCKED}", pg ? " FOR UPDATE SKIP LOCKED" : ""},
  };
  for (const auto& [token, word] : words)
    for (std::size_t at = sql.find(token); at != std::string::npos; at = sql.find(token, at + word.size()))
      sql.replace(at, token.size(), word);
  return sql;
}

Dialect Database::dialect() const {
  return backend_->dialect();
}
Database::Statement Database::prepare(std::string_view sql) {
  return Statement(backend_->prepare(sql));
}
void Database::exec(std::string_view sql) {
  backend_->exec(sql);
}
std::int64_t Database::last_insert_id() const {
  return backend_->last_insert_id();
}
int Database::changes() const {
  return backend_->changes();
}
bool Database::in_transaction() const {
  return backend_->in_transaction();
}
int Database::schema_version() const {
  return backend_->schema_version();
}
int Database::latest_schema_version() {
  return migration_count();
}

namespace {

void check_channel(std::string_view channel) {
  const bool ok =
      !channel.empty() && channel.size() <= 63 && std::all_of(channel.begin(), channel.end(), [](char c) {
        return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
      });
  if (!ok)
    throw StoreError("notification channel '" + std::string(channel.substr(0, 80)) +
                     "': use 1 to 63 lower-case letters, digits or '_'");
}

}  // namespace

void Database::notify(std::string_view channel, std::string_view payload) {
  check_channel(channel);
  if (payload.size() > kMaxNotifyPayload)
    throw StoreError("notification payload of " + std::to_string(payload.size()) + " bytes: at most " +
                     std::to_string(kMaxNotifyPayload));
  backend_->notify(channel, payload);
}

void Database::listen(std::string_view channel) {
  check_channel(channel);
  backend_->listen(channel);
}

std::optional<Database::Notification> Database::wait_notification(std::chrono::milliseconds timeout) {
  auto n = backend_->wait_notification(static_cast<int>(std::max<std::int64_t>(0, timeout.count())));
  if (!n) return std::nullopt;
  return Notification{std::move(n->first), std::move(n->second)};
}

void Database::migrate() {
  if (schema_version() == latest_schema_version()) return;
  Transaction t(*this);  // another process migrating waits here, then finds it done
  const int have = schema_version();
  if (have > latest_schema_version())
    // A downgrade: the older code would misread the newer tables. Nothing is written.
    throw StoreError("the database has schema version " + std::to_string(have) +
                     ", newer than this salientd (" + std::to_string(latest_schema_version()) +
                     "): a newer salientd wrote it. Refusing to open it rather than risk damaging "
                     "it: install the newer salientd again, or restore a backup made by this version");
  for (int v = have; v < latest_schema_version(); ++v) exec(migration_sql(v, dialect()));
  backend_->set_schema_version(latest_schema_version());
  t.commit();
}

Database::Transaction::Transaction(Database& db) : db_(db) {
  db_.backend_->begin_write();
}
Database::Transaction::~Transaction() {
  if (!done_) {
    try {
      db_.exec("ROLLBACK");
    } catch (...) {
    }
  }
}
void Database::Transaction::commit() {
  db_.exec("COMMIT");
  done_ = true;
}

}  // namespace salient::server
